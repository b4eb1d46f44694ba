"""scanfit.dask on a LocalCluster of 2 worker processes: the distributed fits equal
the single-process ones (1e-12 relative, 10^6 points), a killed worker changes
nothing, tiles are read by the workers, bad input is named; and scanfit.sums
pickles exactly.

Needs dask and distributed; without them these tests are skipped with a loud
message, and with SCANFIT_REQUIRE_DASK=1 (CI) they fail instead.
"""

import json
import os
import pickle
import signal
import sys
import threading
import time

import numpy as np
import pytest

import scanfit
import scanfit.sums as S

try:
    import cloudpickle
    import dask.array as da
    from distributed import Client, LocalCluster

    import scanfit.dask as sd
except ImportError as e:  # pragma: no cover - depends on the environment
    msg = f"SKIPPED LOUDLY: dask/distributed missing ({e}); the Dask tests did not run"
    if os.environ.get("SCANFIT_REQUIRE_DASK") == "1":
        raise RuntimeError(msg) from e
    pytest.skip(msg, allow_module_level=True)
else:
    # the slow chunks below are defined here; workers get them by value
    cloudpickle.register_pickle_by_value(sys.modules[__name__])

N = 1_000_000
# rows per chunk, with empty chunks among them
CHUNKS = (0, 300_000, 0, 250_000, 200_000, 250_000)


def terrain(n, seed=5):
    """Scattered terrain far from the origin (the pipelines centre it)."""
    rng = np.random.default_rng(seed)
    x, y = rng.random(n) * 900.0, rng.random(n) * 600.0
    z = 12.0 * np.sin(x / 70.0) * np.cos(y / 55.0) + 0.01 * x + rng.normal(0, 0.05, n)
    return np.column_stack([x + 6.1e5, y + 5.2e6, z])


@pytest.fixture(scope="module")
def pts():
    return terrain(N)


@pytest.fixture(scope="module")
def client():
    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def close(a, b, what):
    """Every coordinate of `a` within 1e-12 of `b`, relative to `b`'s largest
    magnitude in that coordinate."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    scale = np.abs(b).reshape(-1, b.shape[-1]).max(axis=0)
    worst = (np.abs(a - b).reshape(-1, b.shape[-1]).max(axis=0) / scale).max()
    assert worst <= 1e-12, f"{what}: relative difference {worst:.3e}"


def broadcast(k, lattices, start):
    """Bytes of an MBA level state: a header of 120 (tag, centring, frame, next
    lattice), per lattice set a count of 8 and 24 + 8 per value for each lattice
    (the constant's too for the fitted start), the start and the row (24)."""
    sets = 2 if start == "fitted" else 1
    return 120 + sets * (8 + 24 * k + lattices) + (8 if sets == 1 else 0) + 24


def test_mba_on_two_workers_equals_the_single_process_mba(client, pts):
    # the default start: fitted (the constant run through the levels beside the heights)
    once = scanfit.mba(pts, levels=7)
    # the points are sent to the workers once (persisted), not with every pass
    r = sd.mba(client.persist(da.from_array(pts, chunks=(CHUNKS, 3))), levels=7)
    close(r["surface"].control_points, once["surface"].control_points, "control points")
    assert r["cells"] == once["cells"]
    # bounding box, frame, 7 levels, the last level's start, measures
    assert r["points"] == N and r["passes"] == 2 + 7 + 1 + 1
    for a, b in zip(r["levels"], once["levels"]):
        assert a["control_points"] == b["control_points"]
        assert a["vertical"]["rmse"] == pytest.approx(b["vertical"]["rmse"], rel=1e-12)
        assert a["vertical"]["max"] == pytest.approx(b["vertical"]["max"], rel=1e-12)
    # the final residual statistics are those of the last level's report
    assert r["vertical"]["rmse"] == pytest.approx(once["levels"][-1]["vertical"]["rmse"], rel=1e-12)
    # what is broadcast per level is the lattices so far, exactly
    lattices = 0
    for k, sent in enumerate(r["broadcast_bytes"]):
        assert sent == broadcast(k, lattices, "fitted"), (k, sent, lattices)
        m, n = once["levels"][k]["control_points"]
        lattices += 8 * m * n
    # the mean start: the heights' sums alone, one pass fewer
    few = pts[::10]
    mean = sd.mba(client.persist(da.from_array(few, chunks=(30_000, 3))), levels=7, start="mean")
    close(mean["surface"].control_points, scanfit.mba(few, levels=7, start="mean")["surface"].control_points, "mean start")
    assert mean["passes"] == 2 + 7 + 1
    lattices = 0
    for k, sent in enumerate(mean["broadcast_bytes"]):
        assert sent == broadcast(k, lattices, "mean"), (k, sent, lattices)
        m, n = once["levels"][k]["control_points"]
        lattices += 8 * m * n
    small = sd.mba(client.persist(da.from_array(few, chunks=(30_000, 3))), levels=7)
    assert small["broadcast_bytes"] == r["broadcast_bytes"]


def test_fit_surface_on_two_workers_equals_the_single_process_fit(client, pts):
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    uv = (pts[:, :2] - lo[:2]) / (hi[:2] - lo[:2])
    once = scanfit.fit_surface(pts, uv=uv, ctrl=(24, 16), knots="uniform")
    r = sd.fit_surface(
        client.persist(da.from_array(pts, chunks=(CHUNKS, 3))),
        uv=client.persist(da.from_array(uv, chunks=(200_000, 2))),
        ctrl=(24, 16),
        knots="uniform",
    )
    close(r["surface"].control_points, once["surface"].control_points, "control points")
    assert r["smoothing"] == once["smoothing"]
    assert r["points"] == N
    assert r["errors"]["rmse"] == pytest.approx(once["quality"]["rmse"], rel=1e-9)
    assert r["passes"] == 3 and r["rounds"] == []
    # what stays single-process is refused before any pass, with the reason
    with pytest.raises(scanfit.ScanfitError, match="whole cloud"):
        sd.mba(da.from_array(pts), adjust=True)
    with pytest.raises(scanfit.ScanfitError, match="'mean' or 'fitted'"):
        sd.mba(da.from_array(pts), start="zero")
    with pytest.raises(scanfit.ScanfitError, match="a plane cannot close"):
        sd.fit_surface(da.from_array(pts), periodic_u=True)


def knots_close(a, b, what):
    for x, y in zip(a["surface"].knots, b["surface"].knots):
        assert x.shape == y.shape, what
        assert np.abs(x - y).max() <= 1e-12, f"{what}: knots differ by {np.abs(x - y).max():.3e}"


def test_the_default_fit_plane_and_distribution_knots_equals_the_single_process_fit(client, pts):
    # the single-process defaults: parameters from the best-fit plane (covariance,
    # minimum-area rectangle), knots from their distribution (eq. 9.69), the net
    # from the density and the smoothing scaled to the data
    once = scanfit.fit_surface(pts)
    r = sd.fit_surface(client.persist(da.from_array(pts, chunks=(CHUNKS, 3))))
    close(r["surface"].control_points, once["surface"].control_points, "control points")
    knots_close(r, once, "distribution knots")
    # the knots are not the uniform ones (the test would not see a wrong rank otherwise)
    uniform = np.linspace(0, 1, len(once["surface"].knots[0]) - 6)
    assert np.abs(once["surface"].knots[0][3:-3] - uniform).max() > 1e-4
    assert r["smoothing"] == once["smoothing"]
    assert r["errors"]["rmse"] == pytest.approx(once["quality"]["rmse"], rel=1e-9)
    # the terrain does not fold over its best-fit plane: both keep it
    assert r["projection"]["axis"] == once["projection"]["axis"] == "best-fit plane"
    assert r["projection"]["fold_shares"] == once["projection"]["fold_shares"]
    # box, 3 plane passes, 2 rounds of knot counts at 10^6 points, equations, errors
    assert r["passes"] == 1 + 3 + 2 + 2
    # the same on a rotated copy: the plane and its rectangle are not the axes
    c, s = np.cos(0.4), np.sin(0.4)
    rot = pts @ np.array([[c, s, 0.1], [-s, c, 0.0], [-0.1, 0.0, 1.0]]).T
    rot = rot[:200_000]
    once = scanfit.fit_surface(rot, ctrl=(20, 14))
    r = sd.fit_surface(da.from_array(rot, chunks=(70_000, 3)), ctrl=(20, 14))
    close(r["surface"].control_points, once["surface"].control_points, "rotated")
    knots_close(r, once, "rotated")


def franke(n, seed=29):
    """Franke's function (relief about 1.2) on ``n`` seeded uniform points of the
    unit square: its best-fit plane is tilted and folds the bumps over."""
    rng = np.random.default_rng(seed)
    x, y = rng.random(n), rng.random(n)
    z = (
        0.75 * np.exp(-((9 * x - 2) ** 2 + (9 * y - 2) ** 2) / 4)
        + 0.75 * np.exp(-((9 * x + 1) ** 2) / 49 - (9 * y + 1) / 10)
        + 0.5 * np.exp(-((9 * x - 7) ** 2 + (9 * y - 3) ** 2) / 4)
        - 0.2 * np.exp(-((9 * x - 4) ** 2) - (9 * y - 7) ** 2)
    )
    return np.column_stack([x, y, z])


def test_a_folding_height_field_is_projected_along_z_on_the_workers_as_in_one_process(
    client, tmp_path
):
    # the single-process fit projects along z (the best-fit plane folds); the
    # workers gather the same seeded sample (the smallest hashes of the global
    # rows) in the covariance pass, whatever the chunks, tiles and tasks
    p = franke(100_000)
    once = scanfit.fit_surface(p)
    proj = once["projection"]
    assert proj["axis"] == "z" and proj["direction"] == [0.0, 0.0, 1.0]
    assert proj["fold_shares"]["best-fit plane"] > 0.02 and proj["fold_shares"]["z"] == 0.0
    assert proj["sampled"] == 4000
    assert once["quality"]["fold_overs"] == 0
    # relief 1.2: orthogonal RMSE far under 0.1% of it
    assert once["quality"]["rmse_distance"] < 1.2e-3
    chunked = client.persist(da.from_array(p, chunks=((0, 30_000, 0, 45_000, 25_000), 3)))
    sizes = [20_000, 65_000, 15_000]  # tiles, the big one split into tasks
    paths = []
    for k, part in enumerate(np.split(p, np.cumsum(sizes)[:-1])):
        paths.append(tmp_path / f"f{k}.ply")
        scanfit.write_cloud(str(paths[-1]), part)
    for what, r in [
        ("array", sd.fit_surface(chunked)),
        ("tiles", sd.fit_surface(paths, chunk_points=7_000, task_points=30_000)),
    ]:
        assert r["projection"]["axis"] == "z", what
        assert r["projection"]["fold_shares"] == proj["fold_shares"], what
        assert r["projection"]["sampled"] == 4000, what
        close(r["surface"].control_points, once["surface"].control_points, f"franke, {what}")
        knots_close(r, once, f"franke, {what}")
        assert r["errors"]["rmse"] == pytest.approx(once["quality"]["rmse"], rel=1e-9)
    # with a correction round: the same choice, the same corrected surface
    once = scanfit.fit_surface(p[:40_000], ctrl=(16, 16), correct=1)
    r = sd.fit_surface(da.from_array(p[:40_000], chunks=(9_000, 3)), ctrl=(16, 16), correct=1)
    assert r["projection"]["axis"] == once["projection"]["axis"] == "z"
    close(r["surface"].control_points, once["surface"].control_points, "franke, corrected")


def test_a_folding_height_field_gives_one_surface_in_memory_streamed_and_on_dask(
    cli, client, tmp_path
):
    # the command line in memory and with --chunk-points, and Dask: one choice
    p = franke(30_000, seed=31)
    xyz = tmp_path / "franke.xyz"
    np.savetxt(xyz, p, fmt="%.17g")  # exact round trip
    docs = {}
    for what, extra in [("memory", []), ("streamed", ["--chunk-points", "4321"])]:
        out = tmp_path / f"{what}.json"
        rep = cli("fit", xyz, "--no-trim", "-q", "--json", "-o", out, *extra)
        assert rep["projection"]["axis"] == "z", what
        docs[what] = (rep, json.loads(out.read_text()))
    a, b = docs["memory"][0]["projection"], docs["streamed"][0]["projection"]
    for key in ("axis", "direction", "fold_shares", "sampled"):
        assert a[key] == b[key], key
    r = sd.fit_surface(da.from_array(p, chunks=(6_000, 3)))
    assert r["projection"]["fold_shares"] == docs["memory"][0]["projection"]["fold_shares"]
    for what, (_, doc) in docs.items():
        cp = np.asarray(doc["control_points"]).reshape(doc["count_u"], doc["count_v"], 3)
        close(r["surface"].control_points, cp, f"dask vs the command line {what}")
        for x, key in zip(r["surface"].knots, ("knots_u", "knots_v")):
            assert np.abs(x - np.asarray(doc[key])).max() <= 1e-12, (what, key)


def test_parameter_correction_on_the_workers_equals_the_single_process_correction(client, pts):
    # Hoschek's correction: per round the workers re-project their points onto
    # the accepted surfaces in turn; given uv and distribution knots (both
    # recomputed per round, as the single-process fit does)
    sample = pts[:300_000]
    lo, hi = sample.min(axis=0), sample.max(axis=0)
    uv = (sample[:, :2] - lo[:2]) / (hi[:2] - lo[:2])
    uv = uv**1.3  # a poor parameterization that the correction improves
    once = scanfit.fit_surface(sample, uv=uv, ctrl=(16, 12), correct=2)
    r = sd.fit_surface(
        client.persist(da.from_array(sample, chunks=(100_000, 3))),
        uv=client.persist(da.from_array(uv, chunks=(100_000, 2))),
        ctrl=(16, 12),
        correct=2,
    )
    assert len(r["rounds"]) == len(once["rounds"]) >= 2
    for a, b in zip(r["rounds"], once["rounds"]):
        assert a["round"] == b["round"]
        assert a["rmse"] == pytest.approx(b["rmse"], rel=1e-9)
    assert once["rounds"][1]["rmse"] < once["rounds"][0]["rmse"]
    close(r["surface"].control_points, once["surface"].control_points, "corrected")
    knots_close(r, once, "corrected")
    # the default plane with one round
    once = scanfit.fit_surface(sample, ctrl=(16, 12), correct=1)
    r = sd.fit_surface(da.from_array(sample, chunks=(150_000, 3)), ctrl=(16, 12), correct=1)
    close(r["surface"].control_points, once["surface"].control_points, "plane, corrected")
    assert [x["round"] for x in r["rounds"]] == [x["round"] for x in once["rounds"]]


def slow(block):
    time.sleep(0.25)
    return block


def test_a_worker_killed_mid_run_is_retried_and_the_result_is_unchanged(client, pts):
    sample = pts[:200_000]
    base = client.persist(da.from_array(sample, chunks=(20_000, 3)))
    arr = base.map_blocks(slow, dtype=np.float64)
    undisturbed = sd.mba(arr, levels=6)
    pids = client.run(os.getpid)
    out = {}
    run = threading.Thread(target=lambda: out.setdefault("r", sd.mba(arr, levels=6)))
    run.start()
    time.sleep(2.5)  # the passes take about 10 s: bounding box, frame, levels
    assert run.is_alive(), "the run ended before the worker could be killed"
    victim = sorted(pids.values())[0]
    os.kill(victim, signal.SIGKILL)
    run.join(timeout=120)
    assert not run.is_alive()
    assert victim not in client.run(os.getpid).values()  # it did die
    a, b = out["r"]["surface"].control_points, undisturbed["surface"].control_points
    assert np.array_equal(a, b)  # the merge tree is fixed: the same bits
    close(a, scanfit.mba(sample, levels=6)["surface"].control_points, "control points")


def test_tiles_are_read_by_the_workers_and_a_bad_tile_is_named(client, tmp_path):
    p = terrain(90_000, seed=8)
    paths = []
    for k, part in enumerate(np.array_split(p, 3)):
        paths.append(tmp_path / f"tile{k}.ply")
        scanfit.write_cloud(str(paths[-1]), part)
    r = sd.mba(paths, levels=5)
    close(r["surface"].control_points, scanfit.mba(p, levels=5)["surface"].control_points, "tiles")
    # a given domain replaces the bounding-box pass
    lo, hi = p.min(axis=0), p.max(axis=0)
    d = sd.mba(paths, levels=5, domain=(lo[0], lo[1], hi[0], hi[1]), up="z")
    assert d["passes"] == r["passes"] - 1
    close(d["surface"].control_points, r["surface"].control_points, "domain")
    bad = tmp_path / "broken.ply"
    bad.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 10\n")
    with pytest.raises(scanfit.ScanfitError, match="broken.ply"):
        sd.mba([*paths, bad], levels=3)
    with pytest.raises(scanfit.ScanfitError, match=r"tile\d.ply.*no columns named u and v"):
        sd.fit_surface(paths, params="uv", knots="uniform")


def test_point_chunks_serve_the_rows_of_read_cloud_a_bounded_chunk_at_a_time(tmp_path):
    p = terrain(25_000, seed=9)
    uv = np.random.default_rng(1).random((len(p), 2))
    path = tmp_path / "rows.ply"
    scanfit.write_cloud(str(path), p, attributes={"u": uv[:, 0], "v": uv[:, 1]})
    whole = scanfit.read_cloud(str(path)).positions
    rows = scanfit.PointChunks(str(path), 4_000, uv=True, start=6_500, stop=19_000)
    assert rows.bounded  # binary PLY: read a chunk of records at a time
    got = list(rows)
    # the chunks of the reader, cut to [start, stop): never more than chunk_points rows
    assert [len(x) for x, _ in got] == [1_500, 4_000, 4_000, 3_000]
    assert np.array_equal(np.concatenate([x for x, _ in got]), whole[6_500:19_000])
    assert np.array_equal(np.concatenate([u for _, u in got]), uv[6_500:19_000])
    assert rows.rows_read == 20_000  # reading stops at the chunk holding `stop`
    assert [len(x) for x, u in scanfit.PointChunks(str(path), 10_000, start=24_000)] == [1_000]
    with pytest.raises(scanfit.ScanfitError, match="chunk_points must be at least 1"):
        scanfit.PointChunks(str(path), 0)
    with pytest.raises(scanfit.ScanfitError, match="before start"):
        scanfit.PointChunks(str(path), 10, start=5, stop=4)
    with pytest.raises(scanfit.ScanfitError, match="none.ply"):
        scanfit.PointChunks(str(tmp_path / "none.ply"), 100)


def test_a_big_tile_is_split_into_tasks_that_read_it_a_chunk_at_a_time(client, tmp_path):
    p = terrain(200_000, seed=11)
    sizes = [30_000, 150_000, 20_000]  # one big tile between two small ones
    paths = []
    for k, part in enumerate(np.split(p, np.cumsum(sizes)[:-1])):
        paths.append(tmp_path / f"t{k}.ply")
        scanfit.write_cloud(str(paths[-1]), part)
    once = scanfit.mba(p, levels=6)
    r = sd.mba(paths, levels=6, chunk_points=12_000, task_points=40_000)
    # the big tile in 4 tasks of at most 40 000 rows, the small ones whole
    assert r["tasks"] == 1 + 4 + 1
    close(r["surface"].control_points, once["surface"].control_points, "split tiles, mba")
    assert r["points"] == len(p) and r["up"] == once["up"] == "z"
    whole = sd.mba(paths, levels=6, chunk_points=12_000)
    assert whole["tasks"] == 3
    close(whole["surface"].control_points, once["surface"].control_points, "tiles, mba")
    # the default fit (plane, distribution knots) over the split tiles
    fit = scanfit.fit_surface(p, ctrl=(12, 10))
    f = sd.fit_surface(paths, ctrl=(12, 10), chunk_points=12_000, task_points=40_000)
    assert f["tasks"] == 6 and f["points"] == len(p)
    close(f["surface"].control_points, fit["surface"].control_points, "split tiles, fit")
    knots_close(f, fit, "split tiles, fit")
    # a tile cut short is named, whichever of its tasks meets the cut
    cut = tmp_path / "cut.ply"
    cut.write_bytes(paths[1].read_bytes()[:-100_000])
    with pytest.raises(scanfit.ScanfitError, match="tile .*cut.ply could not be read"):
        sd.mba([paths[0], cut], levels=3, chunk_points=12_000, task_points=40_000)
    with pytest.raises(scanfit.ScanfitError, match="task_points must be a positive"):
        sd.mba(paths, task_points=0)
    with pytest.raises(scanfit.ScanfitError, match="chunk_points must be a positive"):
        sd.fit_surface(paths, chunk_points=2.5)


def test_up_on_the_workers_is_the_single_process_up(client, tmp_path):
    zup = terrain(120_000, seed=12)
    # the same terrain stored y-up: world (x, z, -y) is the frame (x, -z, y) turned back
    yup = np.column_stack([zup[:, 0], zup[:, 2], -zup[:, 1]])
    arr = client.persist(da.from_array(yup, chunks=(40_000, 3)))
    once = scanfit.mba(yup, levels=6, up="y")
    r = sd.mba(arr, levels=6, up="y")
    # box (with the sample), frame, 6 levels, the fitted start's pass, the vertical residuals
    assert r["up"] == "y" and r["passes"] == 2 + 6 + 1 + 1
    close(r["surface"].control_points, once["surface"].control_points, "up='y'")
    for a, b in zip(r["levels"], once["levels"]):
        assert a["vertical"]["rmse"] == pytest.approx(b["vertical"]["rmse"], rel=1e-12)
    # auto finds y from the bounding-box pass's sample, as the single-process call does
    auto = sd.mba(arr, levels=6)
    assert auto["up"] == scanfit.mba(yup, levels=6)["up"] == "y"
    assert np.array_equal(auto["surface"].control_points, r["surface"].control_points)
    # z as height is the other surface (a wall of spikes), also as the single-process one
    z = sd.mba(arr, levels=4, up="z")
    close(z["surface"].control_points, scanfit.mba(yup, levels=4, up="z")["surface"].control_points, "z")
    # tiles, x up, with the domain in the x-up frame's (y, z)
    xup = np.column_stack([zup[:, 2], zup[:, 0], zup[:, 1]])
    paths = []
    for k, part in enumerate(np.array_split(xup, 2)):
        paths.append(tmp_path / f"x{k}.ply")
        scanfit.write_cloud(str(paths[-1]), part)
    x = sd.mba(paths, levels=5, up="x", chunk_points=25_000)
    close(x["surface"].control_points, scanfit.mba(xup, levels=5, up="x")["surface"].control_points, "x")
    lo, hi = xup.min(axis=0), xup.max(axis=0)
    d = sd.mba(paths, levels=5, up="x", domain=(lo[1], lo[2], hi[1], hi[2]))
    assert d["passes"] == x["passes"] - 1
    close(d["surface"].control_points, x["surface"].control_points, "x, domain")
    with pytest.raises(scanfit.ScanfitError, match="up = 'w' is not one of"):
        sd.mba(arr, up="w")


def test_bad_points_are_refused_with_the_reason(client):
    with pytest.raises(scanfit.ScanfitError, match=r"shape \(N, 3\)"):
        sd.mba(da.zeros((10, 2), chunks=5))
    with pytest.raises(scanfit.ScanfitError, match="Dask array"):
        sd.mba(np.zeros((10, 3)))
    with pytest.raises(scanfit.ScanfitError, match="empty"):
        sd.mba(da.zeros((0, 3), chunks=(0, 3)))
    nan = da.from_array(np.array([[0.0, 0, 0], [1, 1, 1], [2, np.nan, 1]]), chunks=(2, 3))
    with pytest.raises(scanfit.ScanfitError, match="non-finite"):
        sd.mba(nan, domain=(0, 0, 2, 2))


def test_accumulators_pickle_exactly_and_merge_as_one_pass():
    p = terrain(40_000, seed=3)
    c = S.Centring(tuple(p.min(axis=0)), tuple(p.max(axis=0)))
    assert pickle.loads(pickle.dumps(c)).centre == c.centre
    f = S.FrameSums()
    f.add(p, c)
    for start in ("fitted", "mean"):
        run = S.MbaLevels(pickle.loads(pickle.dumps(f)), c, levels=4, start=start)
        while not run.done:
            state = pickle.loads(pickle.dumps(run.state()))
            a, b = state.accumulator(), state.accumulator()
            sums = a.add(state, p[:15_000])
            sums.merge(pickle.loads(pickle.dumps(b.add(state, p[15_000:]))))
            b2 = pickle.loads(pickle.dumps(b))
            assert b2.to_bytes() == b.to_bytes() and b2.points == 25_000
            a.merge(b2)
            assert not run.record(sums)
            run.push(a)
        # the fitted start of the last level: one more pass
        assert run.needs_pass == (start == "fitted")
        while run.needs_pass:
            state = pickle.loads(pickle.dumps(run.state()))
            sums = state.pass_sums(p[:15_000])
            sums.merge(state.pass_sums(p[15_000:]))
            run.record(sums)
        run.record_last(run.state().residuals(p))
        r = run.finish()
        once = scanfit.mba(p, levels=4, start=start)
        close(r["surface"].control_points, once["surface"].control_points, f"merged by hand, {start}")
        for x, y in zip(r["levels"], once["levels"]):
            assert x["vertical"]["rmse"] == pytest.approx(y["vertical"]["rmse"], rel=1e-12)
    with pytest.raises(scanfit.ScanfitError, match="BA sums"):
        S.BaSums.from_bytes(b"not sums at all")
    with pytest.raises(scanfit.ScanfitError, match="cut short"):
        S.BaSums.from_bytes(b2.to_bytes()[:-9])
    # bytes of the format before the fitted start's second value set are refused as such
    old = b"SFBASUM1" + b2.to_bytes()[8:]
    with pytest.raises(scanfit.ScanfitError, match="version 1, but this scanfit reads version 2"):
        S.BaSums.from_bytes(old)
    with pytest.raises(scanfit.ScanfitError, match="version 1"):
        S.MbaState.from_bytes(b"SFPYMBS1" + bytes(200))
    eq = S.FitSetup(100, c, ctrl=6, params="uv", knots="uniform").equations()
    assert pickle.loads(pickle.dumps(eq)).to_bytes() == eq.to_bytes()


def test_plane_knot_and_correction_sums_by_hand_equal_the_single_process_fit():
    p = terrain(40_000, seed=4)
    c = S.Centring(tuple(p.min(axis=0)), tuple(p.max(axis=0)))
    parts = [p[:9_000], p[9_000:9_000], p[9_000:31_000], p[31_000:]]

    def over(parts, task, empty):
        total = None
        for part in parts:
            x = task(part, pickle.loads(pickle.dumps(empty)))
            x = pickle.loads(pickle.dumps(x))
            total = x if total is None else (total.merge(x) or total)
        return total

    offsets = {id(x): o for x, o in zip(parts, [0, 9_000, 9_000, 31_000])}
    plane = S.PlanePasses(c, p[0], len(p))
    assert plane.projection is None
    # the first pass samples by global row: a chunk without its offset is refused
    moments = plane.stage()
    with pytest.raises(scanfit.ScanfitError, match="offset="):
        moments.accumulator().add(moments, p[:10])
    # its sums of the version before the sample are refused as such
    old = b"SFPYPLA1" + moments.accumulator().to_bytes()[8:]
    with pytest.raises(scanfit.ScanfitError, match="version 1, but this scanfit reads version 2"):
        S.PlaneSums.from_bytes(old)
    while not plane.done:
        stage = pickle.loads(pickle.dumps(plane.stage()))

        def task(part, stage):
            s = stage.accumulator()
            s.add(stage, part, offset=offsets[id(part)])
            return s

        plane.push(over(parts, task, stage))
    # the terrain keeps its best-fit plane, as the single-process fit does
    assert plane.projection["axis"] == "best-fit plane"
    assert plane.projection["sampled"] == 4000
    param = pickle.loads(pickle.dumps(plane.parameterization()))
    first = scanfit.fit_surface(p, ctrl=(9, 7))
    # the plane's parameters, computed per chunk
    got = np.concatenate([param.uv(x) for x in parts])
    close(got, np.column_stack([first["u"], first["v"]]), "plane parameters")
    setup = S.FitSetup(len(p), c, ctrl=(9, 7), correct=1)
    search = setup.knot_search()
    while not search.done:
        q = pickle.loads(pickle.dumps(search.query()))

        def count(part, q):
            k = q.counts()
            k.add(q, param.uv(part))
            return k

        search.push(over(parts, count, q))
    assert search.rounds == 2
    eq = setup.equations(search)

    def add(part, eq):
        e = eq.copy()
        e.add(part, param.uv(part))
        return e

    merged = over(parts, add, eq)
    close(merged.finish().control_points, first["surface"].control_points, "by hand")
    fitted = pickle.loads(pickle.dumps(param.fitted(merged)))
    e = over(parts, lambda part, f: f.errors(part), fitted)
    assert e.stats()["rmse"] == pytest.approx(first["quality"]["rmse"], rel=1e-9)
    nxt = pickle.loads(pickle.dumps(fitted.corrected()))
    assert nxt.rounds == 1 and nxt.plane
    with pytest.raises(scanfit.ScanfitError, match="no fitted surface"):
        nxt.corrected()
    with pytest.raises(scanfit.ScanfitError, match="different stages"):
        S.PlanePasses(c, p[0], len(p)).stage().accumulator().merge(
            S.PlaneSums.from_bytes(over(parts, task, stage).to_bytes())
        )
    with pytest.raises(scanfit.ScanfitError, match="at least 3|needs 3|3 points"):
        S.PlanePasses(c, p[0], 2)
    with pytest.raises(scanfit.ScanfitError, match="rank counts"):
        S.RankCounts.from_bytes(b"junk at all, and more")
