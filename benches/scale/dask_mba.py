"""MBA on a Dask LocalCluster vs the single-process call: time, peak memory per
process, bytes per worker per level (issue 17; BENCHMARKS.md, docs/scale-out.md).

    python benches/scale/dask_mba.py N [--chunk 1000000] [--levels 10] [--workers 2] [--single]

The points are generated on the workers (a deterministic terrain per chunk, seeded
by the chunk's index), so nothing is read or sent by the client; --single also runs
scanfit.mba in this process on the same points (they must fit in memory) and
compares the surfaces. Prints one JSON line.
"""

import argparse
import json
import resource
import time

import numpy as np


def terrain_block(block_id, rows, total):
    """Chunk `block_id` of the terrain: 1000 x 800 data units, a few waves."""
    rng = np.random.default_rng(1000 + block_id)
    x, y = rng.random(rows) * 1000.0, rng.random(rows) * 800.0
    z = 30 * np.sin(x / 90) * np.cos(y / 70) + 5 * np.sin(x / 13)
    return np.column_stack([x + 6.1e5, y + 5.2e6, z])


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("n", type=int)
    ap.add_argument("--chunk", type=int, default=1_000_000)
    ap.add_argument("--levels", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--single", action="store_true")
    a = ap.parse_args()

    import dask.array as da
    from dask import delayed
    from distributed import Client, LocalCluster

    import scanfit
    import scanfit.dask as sd

    sizes = [a.chunk] * (a.n // a.chunk) + ([a.n % a.chunk] if a.n % a.chunk else [])
    blocks = [
        da.from_delayed(delayed(terrain_block)(k, r, a.n), shape=(r, 3), dtype=np.float64)
        for k, r in enumerate(sizes)
    ]
    points = da.concatenate(blocks)
    out = {"points": a.n, "chunk": a.chunk, "levels": a.levels, "workers": a.workers}
    with LocalCluster(
        n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        sent0 = client.run(lambda dask_worker: dask_worker.transfer_outgoing_bytes_total)
        t0 = time.perf_counter()
        r = sd.mba(points, levels=a.levels)
        out["dask_seconds"] = time.perf_counter() - t0
        sent1 = client.run(lambda dask_worker: dask_worker.transfer_outgoing_bytes_total)
        out["dask_passes"] = r["passes"]
        out["broadcast_bytes_per_level"] = r["broadcast_bytes"]
        out["worker_sent_bytes_total"] = {w: sent1[w] - sent0.get(w, 0) for w in sent1}
        out["worker_peak_rss_mb"] = client.run(peak_rss_mb)
        out["client_peak_rss_mb_after_dask"] = peak_rss_mb()
        out["vertical_rmse"] = r["vertical"]["rmse"]
        dask_ctrl = r["surface"].control_points
    if a.single:
        pts = np.concatenate([terrain_block(k, rows, a.n) for k, rows in enumerate(sizes)])
        t0 = time.perf_counter()
        once = scanfit.mba(pts, levels=a.levels)
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
