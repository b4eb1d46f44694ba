"""The Python calls give the command line's results on the shipped samples.

Each test runs a `scanfit` command with `--json` (and `-o` for the
document), the same pipeline from Python with the same settings, and
requires the numbers to be equal: control points, knots and parameters
exactly (the JSON writer's numbers round-trip exactly), report values to
1e-12 relative (measured: exact on this machine; the tolerance only allows
for a different summation order if the thread count differs).
"""

import json

import numpy as np
import pytest

import scanfit

REL = 1e-12


def close(a, b):
    return np.allclose(np.asarray(a, float), np.asarray(b, float), rtol=REL, atol=0)


def assert_surface_equals_doc(surface, doc):
    assert surface.degree == (doc["degree_u"], doc["degree_v"])
    assert surface.counts == (doc["count_u"], doc["count_v"])
    ku, kv = surface.knots
    assert np.array_equal(ku, doc["knots_u"])
    assert np.array_equal(kv, doc["knots_v"])
    cp = np.asarray(doc["control_points"]).reshape(doc["count_u"], doc["count_v"], 3)
    assert np.array_equal(surface.control_points, cp)


def assert_quality(py_quality, cli_quality):
    for key, value in cli_quality.items():
        assert key in py_quality, key
        if isinstance(value, list):
            assert close(py_quality[key], value), key
        else:
            assert close(py_quality[key], value), (key, py_quality[key], value)


def assert_stats(py_stats, cli_stats):
    for key in ("mean", "max", "rmse"):
        assert close(py_stats[key], cli_stats[key]), (key, py_stats[key], cli_stats[key])


def test_fit_surface_equals_cli(cli, data, tmp_path):
    out = tmp_path / "t.json"
    rep = cli("fit", data / "terrain_50k.xyz", "--ctrl", "30x30", "-q", "--json", "-o", out)
    doc = json.loads(out.read_text())
    r = scanfit.fit_surface(scanfit.read_cloud(data / "terrain_50k.xyz"), ctrl=(30, 30))
    assert_surface_equals_doc(r["surface"], doc)
    assert_quality(r["quality"], rep["quality"])
    assert_quality(r["quality"]["samples_to_points"], rep["samples_to_points"])
    # the document's quality holds the same values
    assert_quality(r["quality"], {k: v for k, v in doc["quality"].items()})


def test_mba_with_adjustment_equals_cli(cli, data, tmp_path):
    out = tmp_path / "m.json"
    rep = cli("mba", data / "terrain_50k.xyz", "--levels", "5", "--adjust", "-q", "--json", "-o", out)
    doc = json.loads(out.read_text())
    r = scanfit.mba(scanfit.read_cloud(data / "terrain_50k.xyz"), levels=5, adjust=True)
    assert_surface_equals_doc(r["surface"], doc)
    assert len(r["levels"]) == len(rep["levels"]) == 5
    for py, c in zip(r["levels"], rep["levels"]):
        assert py["level"] == c["level"]
        assert list(py["control_points"]) == c["control_points"]
        assert close(py["grid_rmse"], c["grid_rmse"])
        assert close(py["vertical"]["rmse"], c["vertical_rmse"])
        assert close(py["vertical"]["max"], c["vertical_max"])
        assert py["adjusted"]["steps"] == c["adjust_steps"]
        assert close(py["adjusted"]["grid_rmse"], c["adjusted_grid_rmse"])
        assert close(py["adjusted"]["vertical_rmse"], c["adjusted_vertical_rmse"])
    assert_quality(r["quality"], rep["quality"])


@pytest.mark.parametrize("route", ["pde", "bspline"])
def test_coons_equals_cli(cli, data, tmp_path, route):
    out = tmp_path / "c.json"
    args = ["--pde", "5x5"] if route == "pde" else []
    rep = cli("coons", data / "patch_20k.ply", *args, "-q", "--json", "-o", out)
    doc = json.loads(out.read_text())
    kw = {"pde": (5, 5)} if route == "pde" else {}
    r = scanfit.coons(scanfit.read_cloud(data / "patch_20k.ply"), **kw)
    assert_surface_equals_doc(r["surface"], doc)
    assert r["route"] == rep["route"]
    assert r["projection"] == rep["parameters"]["method"]
    assert int(r["outside"].sum()) == rep["parameters"]["outside"]
    assert_stats(r["coons_errors"], rep["coons_error"])
    fit_error = {k: r["quality"][k2] for k, k2 in (("mean", "mean_error"), ("max", "max_error"), ("rmse", "rmse"))}
    assert_stats(fit_error, rep["fit_error"])
    orth = {k: r["quality"][k2] for k, k2 in (("mean", "mean_distance"), ("max", "max_distance"), ("rmse", "rmse_distance"))}
    assert_stats(orth, rep["orthogonal"])
    if route == "pde":
        assert close(r["pde"]["export_deviation"], rep["export_deviation"])


def test_fit_curve_equals_cli(cli, data, tmp_path):
    out = tmp_path / "cf.json"
    rep = cli("curve", "fit", data / "dataset1.csv", "-q", "--json", "-o", out)
    doc = json.loads(out.read_text())
    pts = scanfit.read_cloud(data / "dataset1.csv").positions
    r = scanfit.fit_curve(pts)
    c = r["curve"]
    assert c.degree == doc["degree"]
    assert np.array_equal(c.knots, doc["knots"])
    assert np.array_equal(c.control_points, doc["control_points"])
    assert np.array_equal(r["params"], doc["params"])
    assert r["method"] == rep["parameterization"]
    assert close(r["condition"], rep["condition"])
    assert_quality(r["quality"], rep["quality"])


def test_compare_curves_equals_cli(cli, data, tmp_path):
    rep = cli("curve", "compare", data / "dataset5.csv", "-q", "--json", "-o", tmp_path / "d5.svg")
    pts = scanfit.read_cloud(data / "dataset5.csv").positions
    rows = scanfit.compare_curves(pts)
    assert [r["method"] for r in rows] == [m["method"] for m in rep["methods"]]
    for py, c in zip(rows, rep["methods"]):
        assert (py["error"] is None) == c["ok"]
        if c["ok"]:
            assert_quality(py["quality"], c["quality"])
            assert close(py["condition"], c["condition"])
        else:
            assert py["error"] == c["error"]


def test_boundary_equals_cli(cli, data, tmp_path):
    rep = cli("cloud", "boundary", data / "patch_20k.ply", "-q", "--json")
    r = scanfit.boundary(scanfit.read_cloud(data / "patch_20k.ply"))
    assert close(r["alpha"], rep["alpha"]) and close(r["spacing"], rep["spacing"])
    assert r["outer"] == rep["outer"]
    assert [list(l["indices"]) for l in r["loops"]] == [l["indices"] for l in rep["loops"]]
    assert [c["index"] for c in r["corners"]] == [c["index"] for c in rep["corners"]]
    assert [c["position"] for c in r["corners"]] == [c["position"] for c in rep["corners"]]
    assert close([c["value"] for c in r["corners"]], [c["angle_degrees"] for c in rep["corners"]])
    assert r["sides"] == rep["sides"]
    assert close(r["plane"]["normal"], rep["plane"]["normal"])


def test_hpr_and_normals_equal_cli(cli, data):
    cloud = scanfit.read_cloud(data / "blob_30k.ply")
    rep = cli("cloud", "hpr", data / "blob_30k.ply", "--view", "0,0,200", "-q", "--json")
    r = scanfit.hpr(cloud, (0, 0, 200))
    assert (len(r["visible"]), r["hidden"]) == (rep["visible"], rep["hidden"])
    rep = cli("cloud", "normals", data / "blob_30k.ply", "-q", "--json")
    r = scanfit.normals(cloud)
    assert r["components"] == rep["components"]
    assert len(r["degenerate"]) == rep["degenerate"]
    assert close(r["mean_variation"], rep["mean_variation"])


def test_turntable_equals_cli(cli, data, tmp_path):
    out = tmp_path / "tt.json"
    rep = cli("turntable", data / "bottle_12k.ply", "-q", "--json", "-o", out)
    doc = json.loads(out.read_text())
    r = scanfit.turntable(scanfit.read_cloud(data / "bottle_12k.ply"))
    assert_surface_equals_doc(r["surface"], doc)
    assert close(r["axis"], rep["axis"]) and close(r["radius"], rep["radius"])
    assert r["visible"] == rep["visible"]
    assert close(r["layer_rmse"], rep["layer_rmse"])
    assert close(r["refine_rmse"], rep["refine_rmse"])
    assert r["beyond_end_layers"] == rep["beyond_end_layers"]
    assert_stats(r["distance_all_points"], rep["distance_all_points"])
    assert_stats(r["surface_to_cloud"], rep["surface_to_cloud"])
    assert_quality(r["quality"], rep["quality"])


def test_reconstruct_equals_cli(cli, data, tmp_path):
    out = tmp_path / "v.json"
    rep = cli("reconstruct", data / "vessel_30k.ply", "-q", "--json", "-o", out)
    doc = json.loads(out.read_text())
    r = scanfit.reconstruct(scanfit.read_cloud(data / "vessel_30k.ply"))
    mine = json.loads(r["model"].to_json())
    # the same geometry and topology, to the last bit
    for key in ("closed", "vertices", "edges", "patches"):
        assert mine[key] == doc[key], key
    assert len(r["patches"]) == len(rep["patches"])
    for py, c in zip(r["patches"], rep["patches"]):
        assert py["id"] == c["id"] and py["sides"] == c["sides"] and py["points"] == c["errors"]["count"]
        assert_stats(py["errors"], c["errors"])
        assert_stats(py["coons_errors"], c["coons"])
    for py, c in zip(r["edges"], rep["edges"]):
        assert list(py["vertices"]) == c["vertices"]
        assert close(py["max_normal_angle_deg"], c["max_normal_angle_deg"])
        assert close(py["curve_error"], c["curve_error"])
    t = rep["totals"]
    assert (r["totals"]["patches"], r["totals"]["edges"], r["totals"]["vertices"]) == (t["faces"], t["edges"], t["corners"])
    assert_stats(r["totals"]["errors"], t["errors"])
