"""MBA on a Dask LocalCluster vs the single-process call: time, peak memory per
process, bytes per worker per level (issue 17; BENCHMARKS.md, docs/scale-out.md).

    python benches/scale/dask_mba.py N [--chunk 1000000] [--levels 10] [--workers 2] [--single]
        [--base MxN] [--ply FILE] [--tiles FILE ...] [--task-points M] [--up auto|x|y|z]
        [--compare JSON] [--save JSON]

The points are generated on the workers (a deterministic terrain per chunk, seeded
by the chunk's index), so nothing is read or sent by the client; with --ply FILE
(a binary little-endian PLY of x, y, z float64 only, e.g. make_franke.py's) each
worker reads its chunks' rows of that file itself instead (the input the CLI
reads). With --tiles FILE ... the workers read the point files themselves with
scanfit.PointChunks, --chunk rows at a time (the tiles' rows must add up to N), and
--task-points M splits tiles of more than M rows into tasks of row ranges (the
report's `dask_tasks`). --single also runs scanfit.mba in this process on the same points (they
must fit in memory) and compares the surfaces; --compare JSON compares with the
surface of a `scanfit mba -o JSON` run (e.g. the streaming CLI's, run.py); --save
JSON writes the Dask surface (scanfit/1 JSON) to compare later. Prints one JSON line.
"""

import argparse
import json
import os
import resource
import time

import numpy as np


def terrain_block(block_id, rows, total):
    """Chunk `block_id` of the terrain: 1000 x 800 data units, a few waves."""
    rng = np.random.default_rng(1000 + block_id)
    x, y = rng.random(rows) * 1000.0, rng.random(rows) * 800.0
    z = 30 * np.sin(x / 90) * np.cos(y / 70) + 5 * np.sin(x / 13)
    return np.column_stack([x + 6.1e5, y + 5.2e6, z])


def ply_layout(path):
    """(header bytes, rows) of a binary little-endian PLY of x, y, z doubles."""
    with open(path, "rb") as f:
        head = b""
        while not head.endswith(b"end_header\n"):
            line = f.readline()
            if not line:
                raise SystemExit(f"{path}: no end_header")
            head += line
    text = head.decode("ascii")
    props = [l.split()[-1] for l in text.splitlines() if l.startswith("property")]
    if "binary_little_endian" not in text or props != ["x", "y", "z"] or "double" not in text:
        raise SystemExit(f"{path}: expected a binary little-endian PLY of double x, y, z")
    rows = int(next(l.split()[-1] for l in text.splitlines() if l.startswith("element vertex")))
    return len(head), rows


def ply_rows(path, offset, start, rows):
    """Rows [start, start + rows) of the PLY body (read on the worker)."""
    a = np.fromfile(path, dtype="<f8", count=3 * rows, offset=offset + 24 * start)
    return a.reshape(rows, 3)


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def cpu_seconds():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("n", type=int)
    ap.add_argument("--chunk", type=int, default=1_000_000)
    ap.add_argument("--levels", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--single", action="store_true")
    ap.add_argument("--base", help="cells of the first lattice, MxN (as the CLI's --base)")
    ap.add_argument("--ply")
    ap.add_argument("--tiles", nargs="+")
    ap.add_argument("--task-points", type=int)
    ap.add_argument("--up", default="auto")
    ap.add_argument("--compare")
    ap.add_argument("--save")
    a = ap.parse_args()

    import dask.array as da
    from dask import delayed
    from distributed import Client, LocalCluster

    import scanfit
    import scanfit.dask as sd

    if a.tiles and (a.single or a.ply):
        raise SystemExit("--tiles reads its own files: compare with --compare JSON, not --single or --ply")
    sizes = [a.chunk] * (a.n // a.chunk) + ([a.n % a.chunk] if a.n % a.chunk else [])
    if a.ply:
        offset, rows = ply_layout(a.ply)
        if rows != a.n:
            raise SystemExit(f"{a.ply} holds {rows} points, not {a.n}")
        starts = np.cumsum([0] + sizes[:-1])
        blocks = [
            da.from_delayed(
                delayed(ply_rows)(a.ply, offset, int(s0), r), shape=(r, 3), dtype=np.float64
            )
            for s0, r in zip(starts, sizes)
        ]
    else:
        blocks = [
            da.from_delayed(delayed(terrain_block)(k, r, a.n), shape=(r, 3), dtype=np.float64)
            for k, r in enumerate(sizes)
        ]
    points = a.tiles or da.concatenate(blocks)
    out = {"points": a.n, "chunk": a.chunk, "levels": a.levels, "workers": a.workers,
           "input": a.tiles or a.ply or "generated on the workers",
           "task_points": a.task_points, "load_before": os.getloadavg()}
    with LocalCluster(
        n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        sent0 = client.run(lambda dask_worker: dask_worker.transfer_outgoing_bytes_total)
        t0 = time.perf_counter()
        base = tuple(int(v) for v in a.base.split("x")) if a.base else None
        tiles = {"chunk_points": a.chunk, "task_points": a.task_points} if a.tiles else {}
        r = sd.mba(points, levels=a.levels, base=base, up=a.up, **tiles)
        out["dask_seconds"] = time.perf_counter() - t0
        out["dask_tasks"] = r["tasks"]
        out["up"] = r["up"]
        sent1 = client.run(lambda dask_worker: dask_worker.transfer_outgoing_bytes_total)
        out["dask_passes"] = r["passes"]
        out["broadcast_bytes_per_level"] = r["broadcast_bytes"]
        out["worker_sent_bytes_total"] = {w: sent1[w] - sent0.get(w, 0) for w in sent1}
        out["worker_peak_rss_mb"] = client.run(peak_rss_mb)
        out["worker_cpu_seconds"] = client.run(cpu_seconds)
        out["load_after"] = os.getloadavg()
        out["client_peak_rss_mb_after_dask"] = peak_rss_mb()
        out["vertical_rmse"] = r["vertical"]["rmse"]
        dask_ctrl = r["surface"].control_points
        if a.save:
            r["surface"].to_json(a.save)
    if a.compare:
        b = scanfit.Surface.read_json(a.compare).control_points
        scale = np.abs(b).reshape(-1, 3).max(axis=0)
        out["compare"] = a.compare
        out["max_relative_difference_to_compare"] = float(
            (np.abs(dask_ctrl - b).reshape(-1, 3).max(axis=0) / scale).max()
        )
    if a.single:
        pts = np.concatenate([terrain_block(k, rows, a.n) for k, rows in enumerate(sizes)])
        t0 = time.perf_counter()
        once = scanfit.mba(pts, levels=a.levels, base=base)
        out["single_seconds"] = time.perf_counter() - t0
        out["single_peak_rss_mb"] = peak_rss_mb()
        b = once["surface"].control_points
        scale = np.abs(b).reshape(-1, 3).max(axis=0)
        out["max_relative_difference"] = float(
            (np.abs(dask_ctrl - b).reshape(-1, 3).max(axis=0) / scale).max()
        )
    print(json.dumps(out))


if __name__ == "__main__":
    main()
