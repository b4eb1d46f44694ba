"""Surface and Curve against an independent evaluator (scipy's BSpline) and
their round trips through every writer."""

import pickle

import numpy as np
import pytest
from scipy.interpolate import BSpline

import scanfit


def basis(knots, degree, x, nu=0):
    """Rows of B-spline basis values (or their nu-th derivatives) at x, by scipy."""
    n = len(knots) - degree - 1
    b = BSpline(knots, np.eye(n), degree, extrapolate=False)
    return (b.derivative(nu) if nu else b)(x)


@pytest.fixture(scope="module")
def terrain(data):
    """A bicubic 30 x 30 least-squares fit with non-uniform knots (from the data)."""
    cloud = scanfit.read_cloud(data / "terrain_50k.xyz")
    return cloud, scanfit.fit_surface(cloud, ctrl=(30, 30))


@pytest.fixture(scope="module")
def patch(data):
    """A B-spline surface of different degrees (2 x 4) on a curved panel."""
    return scanfit.coons(scanfit.read_cloud(data / "patch_20k.ply"), ctrl=(9, 12), degree=(2, 4))["surface"]


def scipy_eval(surface, u, v, ku=0, kv=0):
    (tu, tv), (p, q) = surface.knots, surface.degree
    bu, bv = basis(tu, p, u, ku), basis(tv, q, v, kv)
    return np.einsum("ai,ijk,bj->abk", bu, surface.control_points, bv)


@pytest.mark.parametrize("which", ["terrain", "patch"])
def test_surface_evaluate_equals_scipy_tensor_product(which, terrain, patch):
    s = terrain[1]["surface"] if which == "terrain" else patch
    (u0, u1), (v0, v1) = s.domain
    u = np.linspace(u0, u1, 37)
    v = np.linspace(v0, v1, 41)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    mine = s.evaluate(uu, vv)
    ref = scipy_eval(s, u, v)
    scale = np.ptp(s.control_points.reshape(-1, 3), axis=0).max()
    err = np.abs(mine - ref).max() / scale
    assert err < 1e-12, err
    # the derivatives too, up to second order
    d = s.derivatives(uu, vv, order=2)
    for k, l in [(1, 0), (0, 1), (1, 1), (2, 0), (0, 2)]:
        ref = scipy_eval(s, u, v, k, l)
        rel = np.abs(d[..., k, l, :] - ref).max() / max(np.abs(ref).max(), scale)
        assert rel < 1e-11, (k, l, rel)
    assert np.abs(d[..., 0, 0, :] - mine).max() < 1e-14 * scale
    assert np.all(d[..., 2, 1, :] == 0) and np.all(d[..., 1, 2, :] == 0)


def test_evaluate_shapes_scalars_and_domain(patch):
    assert patch.evaluate(0.5, 0.5).shape == (3,)
    assert patch.evaluate([0.1, 0.2], [0.3, 0.4]).shape == (2, 3)
    assert patch.normal(np.zeros((2, 3)), np.ones((2, 3))).shape == (2, 3, 3)
    n = patch.normal(0.4, 0.6)
    assert abs(np.linalg.norm(n) - 1) < 1e-12
    d = patch.derivatives(0.4, 0.6)
    c = np.cross(d[1, 0], d[0, 1])
    assert np.allclose(n, c / np.linalg.norm(c), atol=1e-14)
    with pytest.raises(scanfit.ScanfitError, match=r"u\[1\] = 1.5 is outside the domain"):
        patch.evaluate([0.5, 1.5], [0.5, 0.5])
    with pytest.raises(scanfit.ScanfitError, match="same shape"):
        patch.evaluate([0.5, 0.2], [0.5])
    with pytest.raises(scanfit.ScanfitError, match="finite"):
        patch.evaluate([np.nan], [0.5])


def test_project_recovers_offset_points(patch):
    rng = np.random.default_rng(3)
    u, v = rng.uniform(0.1, 0.9, 200), rng.uniform(0.1, 0.9, 200)
    n = patch.normal(u, v)
    offset = rng.uniform(-0.05, 0.05, 200)
    pts = patch.evaluate(u, v) + offset[:, None] * n
    pu, pv, dist = patch.project(pts)
    assert np.abs(dist - np.abs(offset)).max() < 1e-9
    assert np.abs(pu - u).max() < 1e-6 and np.abs(pv - v).max() < 1e-6


def test_fit_residuals_and_distances_agree_with_evaluate_and_project(terrain):
    cloud, r = terrain
    s, pts = r["surface"], cloud.positions
    res = np.linalg.norm(pts - s.evaluate(r["u"], r["v"]), axis=1)
    assert np.allclose(res, r["residuals"], rtol=0, atol=1e-9 * np.ptp(pts))
    _, _, d = s.project(pts[:500])
    assert np.allclose(d, r["distances"][:500], rtol=0, atol=1e-9 * np.ptp(pts))
    q = r["quality"]
    assert q["rmse"] == pytest.approx(np.sqrt(np.mean(r["residuals"] ** 2)), rel=1e-12)
    assert q["max_distance"] == pytest.approx(r["distances"].max(), rel=1e-15)


def test_surface_writers_round_trip(patch, tmp_path):
    text = patch.to_json()
    back = scanfit.Surface.from_json(text)
    assert back == patch
    assert np.array_equal(back.control_points, patch.control_points)
    patch.to_json(tmp_path / "s.json")
    assert scanfit.Surface.read_json(tmp_path / "s.json") == patch
    assert pickle.loads(pickle.dumps(patch)) == patch
    step = patch.to_step()
    assert "B_SPLINE_SURFACE_WITH_KNOTS" in step and step.startswith("ISO-10303-21;")
    assert patch.to_step(tmp_path / "s.stp") is None
    written = (tmp_path / "s.stp").read_text()
    assert written.count("B_SPLINE_SURFACE_WITH_KNOTS") == step.count("B_SPLINE_SURFACE_WITH_KNOTS") == 1
    iges = patch.to_iges()
    assert all(len(line) == 80 for line in iges.splitlines())
    m = patch.mesh(samples=(10, 12))
    assert m["vertices"].shape == (11 * 13, 3) and m["triangles"].shape == (2 * 10 * 12, 3)
    assert np.allclose(m["vertices"], patch.evaluate(m["uv"][:, 0], m["uv"][:, 1]), atol=1e-12)
    for ext in ("obj", "ply", "glb"):
        patch.to_mesh(tmp_path / f"m.{ext}", samples=8)
        assert (tmp_path / f"m.{ext}").stat().st_size > 0
    with pytest.raises(scanfit.ScanfitError, match="unknown mesh format"):
        patch.to_mesh(tmp_path / "m.stl")
    with pytest.raises(scanfit.ScanfitError, match="not a scanfit surface document"):
        scanfit.Surface.from_json('{"schema": 1}')
    assert repr(patch).startswith("Surface(degree=(2, 4), control_points=(9, 12), domain=[0, 1] x [0, 1]")


@pytest.fixture(scope="module")
def curve(data):
    pts = scanfit.read_cloud(data / "dataset3.csv").positions
    return pts, scanfit.fit_curve(pts)


def test_curve_equals_scipy_and_interpolates(curve):
    pts, r = curve
    c = r["curve"]
    u = np.linspace(*c.domain, 301)
    ref = BSpline(c.knots, c.control_points, c.degree)(u)
    scale = np.ptp(pts)
    assert np.abs(c.evaluate(u) - ref).max() / scale < 1e-12
    d = c.derivatives(u, order=2)
    for k in (1, 2):
        ref_k = BSpline(c.knots, c.control_points, c.degree).derivative(k)(u)
        assert np.abs(d[:, k] - ref_k).max() / np.abs(ref_k).max() < 1e-11
    # interpolation: through every point at its parameter
    assert np.abs(c.evaluate(r["params"]) - pts).max() / scale < 1e-12
    assert r["quality"]["max_deviation"] < 1e-12 * scale


def test_curve_project_and_writers(curve, tmp_path):
    pts, r = curve
    c = r["curve"]
    u, d = c.project(pts)
    assert np.abs(d).max() < 1e-9 * np.ptp(pts)
    assert np.abs(u - r["params"]).max() < 1e-7
    off = c.evaluate(0.37) + np.array([0.0, 0.0, 0.5])  # the curve is planar (z = 0)
    u, d = c.project(off[None, :])
    assert abs(d[0] - 0.5) < 1e-9 and abs(u[0] - 0.37) < 1e-9
    assert scanfit.Curve.from_json(c.to_json()) == c
    c.to_json(tmp_path / "c.json")
    assert scanfit.Curve.read_json(tmp_path / "c.json") == c
    assert pickle.loads(pickle.dumps(c)) == c
    assert "B_SPLINE_CURVE_WITH_KNOTS" in c.to_step()
    c.to_iges(tmp_path / "c.igs")
    assert (tmp_path / "c.igs").stat().st_size > 0
    assert c.length() == pytest.approx(r["quality"]["length"], rel=1e-3)
    assert repr(c).startswith(f"Curve(degree=3, control_points={len(c.control_points)}, domain=[0, 1]")
