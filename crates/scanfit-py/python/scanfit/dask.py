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
paths the workers can read) that the workers read themselves, once per pass, a chunk
of ``chunk_points`` rows at a time (``scanfit.PointChunks``, the reader of
``--chunk-points``): a worker's memory is bounded by the chunk, not the tile, and
with ``task_points`` a big tile is split into several tasks of row ranges. A tile
that fails to read raises a ``ScanfitError`` naming the tile.

The keywords are those of ``scanfit.mba`` and ``scanfit.fit_surface``, with their
defaults. The fit's settings that look at all points at once run as more passes of
mergeable sums: ``params="plane"`` (covariance sums for the plane and, in the same
pass, the seeded sample that chooses the projection direction: the 4000 points of
smallest hash of their global row, merged across tasks, so the workers choose the
best-fit plane or a coordinate axis exactly as the single-process fit does; the
convex hull in the projection plane for the minimum-area rectangle, the extents
along its axes; then every worker computes its points' parameters),
``knots="distribution"`` (the few order
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

from ._scanfit import PointChunks, ScanfitError, Surface, up_axis
from .sums import (
    Centring,
    FitSetup,
    FrameSums,
    MbaLevels,
    Parameterization,
    PassSums,
    PlanePasses,
    ResidualSums,
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


class _Tile:
    """Rows ``start`` to ``stop`` of a tile, read by the task that sums them a
    chunk of ``chunk`` rows at a time (``scanfit.PointChunks``): the points
    never leave that task, and its memory is bounded by the chunk, not the tile."""

    def __init__(self, path, uv, chunk, start=0, stop=None):
        self.path, self.uv, self.chunk, self.start, self.stop = path, uv, chunk, start, stop

    def part(self, start, stop):
        """The rows ``start`` to ``stop`` of the same tile."""
        return _Tile(self.path, self.uv, self.chunk, start, stop)

    def blocks(self):
        """``(points, uv)`` per chunk; a read error names the tile."""
        try:
            for pts, uv in PointChunks(self.path, self.chunk, self.uv, self.start, self.stop):
                yield pts, uv
        except ScanfitError as e:  # the message names the file too; say it is a tile
            raise ScanfitError(f"tile {self.path!s} could not be read: {e}") from None


def _blocks(part, up="z"):
    """The points of a part (in the z-up frame of ``up``) and their parameters,
    a bounded block at a time: a tile's chunks, or a Dask array's block."""
    for pts, uv in part.blocks() if isinstance(part, _Tile) else (part,):
        yield _to_frame(pts, up), uv


def _to_frame(pts, up):
    """Points in the z-up frame of the axis ``up`` (``scanfit.mba``'s, a rotation:
    y up gives ``(x, -z, y)``, x up ``(y, z, x)``; exact, no rounding)."""
    if up == "z":
        return pts
    if up == "y":
        return np.column_stack([pts[:, 0], -pts[:, 2], pts[:, 1]])
    return np.ascontiguousarray(pts[:, [1, 2, 0]])


def _from_frame(pts, up):
    """The inverse of ``_to_frame``."""
    if up == "z":
        return pts
    if up == "y":
        return np.stack([pts[..., 0], pts[..., 2], -pts[..., 1]], axis=-1)
    return np.stack([pts[..., 2], pts[..., 0], pts[..., 1]], axis=-1)


def _surface_from_frame(surface, up):
    """A surface fitted in the z-up frame of ``up``, turned back to world axes
    (its control points turned, exactly; knots unchanged)."""
    if up == "z":
        return surface
    import json

    doc = json.loads(surface.to_json())
    node = doc["surface"] if "surface" in doc else doc
    node["control_points"] = _from_frame(np.asarray(node["control_points"]), up).tolist()
    return Surface.from_json(json.dumps(doc))


def _block(pts, uv):
    """A block of a Dask array (and its parameters) as the accumulators take it."""
    return np.ascontiguousarray(pts, dtype=np.float64), uv


def _parts(points, uv, params, chunk_points):
    """One part per chunk or tile, in a fixed order: a Delayed ``(points, uv)`` per
    chunk of a Dask array, a ``_Tile`` (read by the task that sums it, a chunk of
    ``chunk_points`` rows at a time) per file."""
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
        return [_Tile(str(p), params == "uv", int(chunk_points)) for p in points]
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


def _bounds(part, sample=False):
    """Bounding box, first point and count of a part (``None`` when empty),
    the counts per part, and with ``sample`` an evenly spaced sample (``_Sample``)."""
    lo = hi = first = None
    n = 0
    picked = _Sample() if sample else None
    for pts, _ in _blocks(part):
        if len(pts) == 0:
            continue
        if first is None:
            lo, hi, first = pts.min(axis=0), pts.max(axis=0), pts[0].copy()
        else:
            lo, hi = np.minimum(lo, pts.min(axis=0)), np.maximum(hi, pts.max(axis=0))
        if picked is not None:
            picked.add(pts)
        n += len(pts)
    if first is None:
        return None, [0]
    return (lo, hi, n, first, picked), [n]


def _merge_bounds(*bs):
    """Merged in part order: the first point is the first part's, the counts
    per part follow one another."""
    counts = [c for b in bs for c in b[1]]
    bs = [b[0] for b in bs if b[0] is not None]
    if not bs:
        return None, counts
    lo = np.min([b[0] for b in bs], axis=0)
    hi = np.max([b[1] for b in bs], axis=0)
    picked = None if bs[0][4] is None else _Sample.merged([b[4] for b in bs])
    return (lo, hi, sum(b[2] for b in bs), bs[0][3], picked), counts


#: most points of the sample ``up="auto"`` decides from (as ``scanfit mba --chunk-points``)
UP_SAMPLE = 1 << 16


class _Sample:
    """Every ``stride``-th point of a part (``stride`` a power of two, the
    smallest that keeps at most ``UP_SAMPLE`` points), as the streamed CLI
    samples its input for the automatic up axis."""

    def __init__(self):
        self.points, self.stride, self.seen = np.empty((0, 3)), 1, 0

    def add(self, pts):
        first = (-self.seen) % self.stride  # the next index that is a multiple of stride
        self.points = np.concatenate([self.points, pts[first :: self.stride]])
        self.seen += len(pts)
        while len(self.points) > UP_SAMPLE:
            self.points, self.stride = self.points[::2], 2 * self.stride

    @staticmethod
    def merged(samples):
        """One sample of parts that follow one another: every part thinned to
        the largest stride (so each keeps every ``stride``-th of its points)."""
        out = _Sample()
        out.stride = max(s.stride for s in samples)
        out.points = np.concatenate([s.points[:: out.stride // s.stride] for s in samples])
        while len(out.points) > UP_SAMPLE:
            out.points, out.stride = out.points[::2], 2 * out.stride
        return out


def _frame(part, centring, up="z"):
    f = FrameSums()
    for pts, _ in _blocks(part, up):
        f.add(pts, centring)
    return f


def _level(part, state, up="z"):
    acc, sums = state.accumulator(), PassSums()
    for pts, _ in _blocks(part, up):
        sums.merge(acc.add(state, pts))
    return acc, sums


def _vertical(part, state, up="z"):
    stats = ResidualSums()
    for pts, _ in _blocks(part, up):
        stats.merge(state.residuals(pts))
    return stats


def _start_pass(part, state, up="z"):
    """The pass sums of a part without a level (the fitted start of the last)."""
    sums = PassSums()
    for pts, _ in _blocks(part, up):
        sums.merge(state.pass_sums(pts))
    return sums


def _plane(part, offset, stage):
    """A plane pass's sums of a part whose first point is the global row
    ``offset`` (the first pass samples points by their global row)."""
    sums = stage.accumulator()
    for pts, _ in _blocks(part):
        sums.add(stage, pts, offset=offset)
        offset += len(pts)
    return sums


def _ranks(part, param, query):
    counts = query.counts()
    for pts, uv in _blocks(part):
        counts.add(query, param.uv(pts, uv))
    return counts


def _equations(part, param, empty):
    eq = empty.copy()
    for pts, uv in _blocks(part):
        if len(pts):
            eq.add(pts, param.uv(pts, uv))
    return eq


def _errors(part, param):
    stats = ResidualSums()
    for pts, uv in _blocks(part):
        stats.merge(param.errors(pts, uv))
    return stats


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


def _pass(client, parts, task, *args, merge=_merge, offsets=None):
    """One pass: ``task(part, *args)`` per part (``task(part, offset, *args)``
    with the parts' first global rows ``offsets``), merged in a fixed tree,
    computed."""
    from dask import delayed

    fn = delayed(task, pure=True)
    if offsets is None:
        items = [fn(p, *args) for p in parts]
    else:
        items = [fn(p, o, *args) for p, o in zip(parts, offsets)]
    join = delayed(merge, pure=True)
    while len(items) > 1:
        items = [join(*items[i : i + FAN_IN]) for i in range(0, len(items), FAN_IN)]
    return client.compute(items[0]).result()


def _survey(client, parts, sample=False):
    """The bounding-box pass: ``(lo, hi, count, first point, sample)`` in world
    axes (the sample, a ``_Sample``, with ``sample``) and the counts per part."""
    box, counts = _pass(client, parts, _bounds, sample, merge=_merge_bounds)
    if box is None:
        raise ScanfitError("the points are empty: no chunk or tile holds a point")
    return box, counts


def _centring(box, domain, up="z"):
    """The centring from the surveyed box (turned into the z-up frame of
    ``up``) or from the given domain (in that frame's x and y)."""
    if domain is not None:
        x0, y0, x1, y1 = (float(v) for v in domain)
        return Centring((x0, y0, 0.0), (x1, y1, 0.0))
    corners = _to_frame(np.array([box[0], box[1]], dtype=np.float64), up)
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    return Centring(tuple(map(float, lo)), tuple(map(float, hi)))


def _split(parts, counts, task_points):
    """Tiles of more than ``task_points`` rows as several tasks of at most that
    many rows each (in file order); other parts as they are. Returns the parts
    and their rows."""
    if task_points is None:
        return parts, counts
    out, rows = [], []
    for part, n in zip(parts, counts):
        if isinstance(part, _Tile) and n > task_points:
            for a in range(0, n, task_points):
                out.append(part.part(a, min(a + task_points, n)))
                rows.append(min(a + task_points, n) - a)
        else:
            out.append(part)
            rows.append(n)
    return out, rows


def _offsets(rows):
    """The global row of each part's first point: the rows of the parts before
    it (the index a single-process call gives that point)."""
    return [int(x) for x in np.cumsum([0] + list(rows[:-1]))]


def _check_reading(chunk_points, task_points):
    """Refuses chunk and task sizes that are not positive integers."""
    for name, value in (("chunk_points", chunk_points), ("task_points", task_points)):
        if value is None and name == "task_points":
            continue
        if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
            raise ScanfitError(
                f"{name} must be a positive number of rows; got {value!r}"
            )


def _check_up(up):
    """``up`` as given, refused unless it is one of ``scanfit.mba``'s choices."""
    if up not in ("auto", "x", "y", "z"):
        raise ScanfitError(f'up = {up!r} is not one of "auto", "x", "y", "z"')
    return up


def _mba_survey(client, parts, domain, up, task_points):
    """The bounding-box pass of ``mba`` when it is needed (no domain, the
    automatic up axis, or tiles to split): the parts (split), the up axis
    (decided), the box (``None`` without the pass) and the passes made."""
    tiles = any(isinstance(p, _Tile) for p in parts)
    if domain is not None and up != "auto" and not (tiles and task_points is not None):
        return parts, up, None, 0
    box, counts = _survey(client, parts, sample=up == "auto")
    if up == "auto":
        up = up_axis(box[4].points)
    return _split(parts, counts, task_points)[0], up, box, 1


# ---- the fits (run on the client) ----------------------------------------------


def _mba_start(start):
    """The distributed MBA's start of level 0 (``None``: ``"fitted"``)."""
    if start is None:
        return "fitted"
    if start not in ("mean", "fitted"):
        raise ScanfitError(f"start must be 'mean' or 'fitted'; got {start!r}")
    return start


def _last_start(client, parts, run, up="z"):
    """The fitted start of the last level: one more pass while ``run`` needs it.
    Returns the passes made (0 for the mean start)."""
    passes = 0
    while run.needs_pass:
        run.record(_pass(client, parts, _start_pass, _shared(run.state()), up))
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
    up="auto",
    *,
    domain=None,
    chunk_points=1_000_000,
    task_points=None,
    client=None,
):
    """Multilevel B-spline approximation ``z = f(x, y)`` on the current Dask client.

    The keywords are ``scanfit.mba``'s (``levels``, ``base``, ``tolerance``,
    ``hjelle``, ``start``: ``"fitted"``, the default, or ``"mean"``; ``up``);
    ``adjust=True`` is refused (the projection adjustment finds the nearest points
    of the whole cloud per knot; ``alpha``, ``weight`` and ``adjust_steps`` belong
    to it).

    Parameters:
        points: a Dask array ``(N, 3)`` chunked by rows, or a list of point files.
        up: the height axis, as ``scanfit.mba``'s: ``"x"``, ``"y"``, ``"z"``, or
            ``"auto"`` (the default: the thin axis of a sheet, else z), decided as
            ``scanfit mba --chunk-points`` decides it, from an evenly spaced
            sample of at most 2^16 points of the bounding-box pass (every
            ``2^k``-th point of each chunk or tile). The fit runs in that axis's
            z-up frame (y up: ``y = f(x, -z)``; x up: ``x = f(y, z)``) and the
            surface is turned back, as ``scanfit.mba`` does.
        domain: ``(x0, y0, x1, y1)`` in data units (the horizontal coordinates
            of the up frame: x, y when z is up): the rectangle the lattice
            covers (points outside are clamped to its border), instead of a first
            pass for the data's bounding box. Tiles of one survey then share it
            whatever each holds. Without it the result equals ``scanfit.mba``'s.
            With ``up="auto"`` the pass still runs, for the sample.
        chunk_points: rows a task reads from a tile at a time: a worker's memory
            is bounded by it (about 50 bytes per row), not by the tile's size.
        task_points: split tiles of more rows into tasks of at most this many
            rows (from the bounding-box pass's counts, which then always runs),
            so one big tile is summed by several workers. The readers cannot
            seek, so a task reads and drops the rows before its own: a tile in
            ``k`` tasks costs about ``(k + 1) / 2`` reads of it per pass.
        client: a ``distributed.Client`` (default: the current one).

    Passes over the points: bounding box (unless ``domain`` with an ``up``
    axis given and tiles not split), frame, one per level, with the fitted
    start one for the last level's start, one to measure the final vertical
    residuals.

    Returns a dict: ``surface`` (a ``Surface``), ``up`` (the axis used),
    ``tasks`` (tasks per pass), ``cells``, ``levels`` (per level:
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
    _check_up(up)
    _check_reading(chunk_points, task_points)
    client = _client(client)
    parts = _parts(points, None, None, chunk_points)
    parts, up, box, passes = _mba_survey(client, parts, domain, up, task_points)
    centring = _centring(box, domain, up)
    frame = _pass(client, parts, _frame, centring, up)
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
    passes += 1
    sent = []
    while not run.done:
        state = run.state()
        sent.append(len(state.to_bytes()))
        shared = _shared(state)
        acc, sums = _pass(client, parts, _level, shared, up)
        passes += 1
        if run.record(sums):
            break
        run.push(acc)
    passes += _last_start(client, parts, run, up)
    state = run.state()
    shared = _shared(state)
    vertical = _pass(client, parts, _vertical, shared, up)
    passes += 1
    run.record_last(vertical)
    r = run.finish()
    r["surface"] = _surface_from_frame(r["surface"], up)
    r["up"] = up
    r["tasks"] = len(parts)
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
    chunk_points=1_000_000,
    task_points=None,
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

    With ``params="plane"`` the points are projected onto their best-fit plane,
    or along the x, y or z axis when that plane folds them over and the axis
    does not, chosen as ``scanfit.fit_surface`` chooses it: from the normals of
    the same seeded sample of 4000 points (the smallest hashes of their global
    rows: a point's row is its row in the Dask array, or the rows of the
    tiles before it plus its row in its tile), gathered in the covariance pass
    and merged across tasks; so the surface is the single-process one on
    folding data too.

    Passes over the points: bounding box, count and first point; with the
    plane 3 (covariance sums with the sample, convex hull, extents); then per fit (one, plus
    one per correction round): with distribution knots 2 to 3 rounds of
    counts (more above about 10^9 points), the normal equations, the errors at
    the parameters. Correction round ``r`` re-projects every point onto the
    surfaces of the ``r`` accepted rounds before, in turn (no parameter is
    stored between passes), so its passes cost ``r`` projections per point.

    ``chunk_points`` and ``task_points`` are ``scanfit.dask.mba``'s: the rows
    a task reads from a tile at a time, and the most rows of a tile one task
    sums (bigger tiles are split into several tasks).

    Returns a dict: ``surface``, ``smoothing`` (the weight used), ``points``,
    ``tasks`` (tasks per pass),
    ``errors`` (statistics of ``|p - S(u, v)|`` at the final parameters:
    ``count``, ``mean``, ``max``, ``max_index``, ``rmse``), ``rounds`` (per
    fit: ``round``, ``rmse``, ``max``; as ``scanfit.fit_surface``'s, empty
    without correction), ``passes``, ``seconds``, ``equation_bytes`` (the size
    of the sums each task returns), ``projection`` (with the plane:
    ``scanfit.fit_surface``'s ``projection``, the direction and the fold shares
    that chose it; ``None`` with given parameters).

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
    _check_reading(chunk_points, task_points)
    parts = _parts(points, uv, given, chunk_points)
    box, counts = _survey(client, parts)
    parts, rows = _split(parts, counts, task_points)
    centring, count, first = _centring(box, None), box[2], box[3]
    setup = FitSetup(count, centring, ctrl, degree, given, knots, smooth, periodic_u, correct)
    passes = 1
    if setup.plane:
        plane = PlanePasses(centring, tuple(map(float, first)), count)
        offsets = _offsets(rows)
        while not plane.done:
            stage = _shared(plane.stage())
            plane.push(_pass(client, parts, _plane, stage, offsets=offsets))
            passes += 1
        param, projection = plane.parameterization(), plane.projection
    else:
        param, projection = Parameterization.given(centring), None

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
        "tasks": len(parts),
        "seconds": time.perf_counter() - t0,
        "equation_bytes": eq.nbytes,
        "projection": projection,
    }
