"""Every pipeline binding on data whose answer is known."""

import threading
import time

import numpy as np
import pytest

import scanfit


def plane_grid(n=10):
    i = np.arange(n * n)
    x, y = (i % n).astype(float), (i // n).astype(float)
    return np.column_stack([x, y, 0.5 * x])


def test_normals_of_a_tilted_plane():
    r = scanfit.normals(plane_grid())
    expect = np.array([-0.5, 0.0, 1.0]) / np.sqrt(1.25)
    assert np.abs(r["normals"] - expect).max() < 1e-9
    assert r["mean_variation"] < 1e-12 and r["components"] == 1
    c = r["cloud"]
    assert np.array_equal(c.attributes["nx"], r["normals"][:, 0])
    assert np.array_equal(c.attributes["variation"], r["variation"])
    down = scanfit.normals(plane_grid(), orient="view", viewpoint=(4.5, 4.5, -100))
    assert np.abs(down["normals"] + expect).max() < 1e-9


def sphere(n=400):
    z = 1 - (2 * np.arange(n) + 1) / n
    r = np.sqrt(1 - z * z)
    t = np.arange(n) * 2.399963
    return np.column_stack([r * np.cos(t), r * np.sin(t), z])


def test_hpr_sees_about_half_a_sphere():
    r = scanfit.hpr(sphere(), viewpoint=(0, 0, 100))
    vis = r["visible"]
    assert len(vis) + r["hidden"] == 400 and 160 < len(vis) < 240
    assert r["mask"].sum() == len(vis) and r["mask"][vis].all()
    assert (sphere()[vis][:, 2] > -0.2).all()  # what is seen faces the viewpoint
    assert np.array_equal(r["cloud"].attributes["index"], vis.astype(float))


def square(n=41, bend=0.02):
    x, y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 7, 29))
    return np.column_stack([x.ravel(), y.ravel(), bend * (x * y).ravel()])


def test_boundary_corners_of_a_panel():
    pts = square(bend=0.0)
    r = scanfit.boundary(pts)
    corners = sorted(tuple(np.round(pts[c["index"], :2]).astype(int)) for c in r["corners"])
    assert corners == [(0, 0), (0, 7), (10, 0), (10, 7)]
    assert len(r["loops"]) == 1 and r["loops"][0]["area"] == pytest.approx(70, rel=1e-9)
    assert [s[0] for s in r["sides"]] == [c["index"] for c in r["corners"]]
    assert abs(abs(r["plane"]["normal"][2]) - 1) < 0.01
    loop_only = scanfit.boundary(pts, corners=0)
    assert loop_only["corners"] is None and loop_only["sides"] is None


@pytest.mark.parametrize("pde", [None, (4, 4)])
def test_coons_reproduces_a_bilinear_patch(pde):
    # z = 0.02 x y is its own Coons patch: both routes fit it closely
    r = scanfit.coons(square(), pde=pde, **({} if pde else {"ctrl": (8, 8)}))
    assert len(r["corners"]) == 4 and len(r["boundary_curves"]) == 4
    # closest points are exact; the grid iteration stops within its epsilon
    # (0.01 data units; measured max 0.0032)
    tol = 1e-3 if pde else 0.01
    assert r["quality"]["max_error"] < tol and r["coons_errors"]["max"] < tol
    assert r["projection"] == ("closest" if pde else "grid")
    if pde:
        assert r["pde"]["export_deviation"] <= r["pde"]["export_tolerance"]
    s = r["surface"]
    p = s.evaluate(r["u"], r["v"])
    assert np.abs(np.linalg.norm(p - square(), axis=1) - r["residuals"]).max() < 1e-12


def test_mba_levels_lower_the_error_and_vertical_is_z_minus_f():
    k = np.arange(3000)
    t = k * 0.61803398875
    x, y = 40 * (t % 1), 30 * k / 3000
    pts = np.column_stack([x, y, 3 * np.sin(x / 7) + np.cos(y / 5)])
    r = scanfit.mba(pts, levels=4)
    rmse = [l["vertical"]["rmse"] for l in r["levels"]]
    assert len(rmse) == 4 and all(b < a for a, b in zip(rmse, rmse[1:]))
    f = r["surface"].evaluate(r["u"], r["v"])
    assert np.allclose(np.abs(pts[:, 2] - f[:, 2]), r["vertical"], rtol=0, atol=1e-12)
    # x and y are linear in u and v: the surface is a height field over the box
    assert np.allclose(f[:, :2], pts[:, :2], atol=1e-9)
    adj = scanfit.mba(pts, levels=4, adjust=True, weight="aza04")
    assert adj["levels"][-1]["adjusted"]["steps"] > 0
    assert adj["quality"]["grid_rmse"] < r["levels"][-1]["grid_rmse"]
    assert scanfit.mba(pts, levels=2, base=(3, 2))["cells"] == (6, 4)


def test_fit_surface_with_given_periodic_parameters():
    # a cylinder r = 2, parameters given: u around, v along
    u, v = np.meshgrid(np.linspace(0, 1, 60, endpoint=False), np.linspace(0, 1, 20))
    u, v = u.ravel(), v.ravel()
    pts = np.column_stack([2 * np.cos(2 * np.pi * u), 2 * np.sin(2 * np.pi * u), 5 * v])
    r = scanfit.fit_surface(pts, uv=np.column_stack([u, v]), periodic_u=True, ctrl=(16, 4), smooth=0)
    s = r["surface"]
    assert s.periodic == (True, False)
    assert r["quality"]["max_error"] < 2e-3 and r["smoothing"] == 0
    # by default the thin-plate weight is scaled to the data: 0.001 x points / (nu x nv)^2
    dflt = scanfit.fit_surface(pts, uv=np.column_stack([u, v]), periodic_u=True, ctrl=(16, 4))
    assert dflt["smoothing"] == pytest.approx(0.001 * 1200 / (16 * 4) ** 2, rel=1e-12)
    assert np.allclose(r["u"], u) and np.allclose(r["v"], v)
    # the seam closes: S(0, v) = S(1, v)
    assert np.abs(s.evaluate(0.0, 0.5) - s.evaluate(1.0, 0.5)).max() < 1e-12
    c = scanfit.Cloud(pts, {"u": u, "v": v})
    r2 = scanfit.fit_surface(c, params="uv", periodic_u=True, ctrl=(16, 4), smooth=0)
    assert r2["surface"] == s
    corrected = scanfit.fit_surface(scanfit.Cloud(pts), ctrl=(6, 6), correct=3)
    assert corrected["rounds"][0]["round"] == 0


def test_curve_least_squares_and_closed():
    t = np.linspace(0, 1, 60)
    pts = np.column_stack([t, np.sin(3 * t), 0 * t])
    r = scanfit.fit_curve(pts, ctrl=8)
    assert len(r["curve"].control_points) == 8 and r["kind"] == "least squares"
    assert np.array_equal(r["curve"].control_points[0], pts[0])  # pinned ends
    free = scanfit.fit_curve(pts, ctrl=8, free_ends=True)
    assert free["quality"]["rms_deviation"] <= r["quality"]["rms_deviation"]
    a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    loop = scanfit.fit_curve(np.column_stack([np.cos(a), 2 * np.sin(a), 0 * a]), closed=True)
    assert loop["curve"].periodic and loop["method"] == "centripetal"
    tangents = scanfit.fit_curve(pts, end_tangents=((1, 3, 0), (1, 3 * np.cos(3), 0)))
    d = tangents["curve"].derivatives([0.0, 1.0])
    assert np.allclose(d[:, 1], [[1, 3, 0], [1, 3 * np.cos(3), 0]], atol=1e-9)
    rows = scanfit.compare_curves(pts[::6], methods=["chord", "centripetal", "proposed:0.5"])
    assert [r["method"] for r in rows] == ["chord", "centripetal", "proposed"]


def test_reconstruct_the_umbrella(data, tmp_path):
    r = scanfit.reconstruct(scanfit.read_cloud(data / "umbrella_20k.ply"))
    m = r["model"]
    assert repr(m) == "Model(8 patches, 16 edges, 9 vertices, open)" and not m.closed
    assert all(p["sides"] == 3 for p in r["patches"])
    assert r["totals"]["max_gap"] < 1e-12 * r["totals"]["diagonal"]
    assert len(m.surfaces) == 8 and len(m.edge_curves) == 16
    m.to_step(tmp_path / "u.stp")
    m.to_iges(tmp_path / "u.igs")
    assert "OPEN_SHELL" in (tmp_path / "u.stp").read_text()
    assert (tmp_path / "u.igs").stat().st_size > 0
    bs = scanfit.reconstruct(scanfit.read_cloud(data / "umbrella_20k.ply"), fit="bspline", ctrl=6)
    # at least 6 x 6: more where the side curves bring knots (their rows are the boundary)
    counts = [p["surface"].counts for p in bs["patches"]]
    assert all(cu >= 6 and cv >= 6 for cu, cv in counts)
    assert bs["totals"]["max_gap"] < 1e-12 * bs["totals"]["diagonal"]


def test_the_gil_is_released_while_the_library_computes(data):
    cloud = scanfit.read_cloud(data / "terrain_50k.xyz")
    done = threading.Event()

    def work():
        scanfit.fit_surface(cloud, ctrl=(40, 40))
        done.set()

    th = threading.Thread(target=work)
    t0 = time.perf_counter()
    th.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    th.join()
    elapsed = time.perf_counter() - t0
    # the main thread kept running Python during the fit (about one tick
    # per millisecond); with the GIL held it would get a handful at most
    assert elapsed > 0.05 and ticks > 0.1 * elapsed * 1000, (ticks, elapsed)


def test_mba_takes_the_thin_axis_of_a_y_up_sheet_as_height():
    rng = np.random.default_rng(7)
    x, y = rng.uniform(0, 40, 3000), rng.uniform(0, 30, 3000)
    zup = np.c_[x, y, 2.0 * np.sin(x / 7.0) + np.cos(y / 5.0)]
    # the same terrain stored y-up: (x, y, z) -> (x, z, -y)
    yup = np.c_[zup[:, 0], zup[:, 2], -zup[:, 1]]
    flat = scanfit.mba(zup, levels=4)
    turned = scanfit.mba(yup, levels=4)
    assert (flat["up"], turned["up"]) == ("z", "y")
    cz = flat["surface"].control_points.reshape(-1, 3)
    cy = turned["surface"].control_points.reshape(-1, 3)
    # exactly the z-up net turned
    assert np.array_equal(cy, np.c_[cz[:, 0], cz[:, 2], -cz[:, 1]])
    wall = scanfit.mba(yup, levels=4, up="z")
    assert wall["quality"]["rmse_distance"] > 5 * turned["quality"]["rmse_distance"]
    with pytest.raises(scanfit.ScanfitError, match="up"):
        scanfit.mba(yup, up="w")
