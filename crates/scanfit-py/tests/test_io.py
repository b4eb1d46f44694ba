"""read_cloud / write_cloud against an independent reader (numpy) and
their own round trips."""

import numpy as np
import pytest

import scanfit


def test_read_text_equals_numpy(data):
    cloud = scanfit.read_cloud(data / "terrain_50k.xyz")
    ref = np.loadtxt(data / "terrain_50k.xyz")
    assert cloud.positions.dtype == np.float64
    assert np.array_equal(cloud.positions, ref)
    assert len(cloud) == 50000 and cloud.attributes == {}
    assert cloud.path.endswith("terrain_50k.xyz")
    assert repr(cloud).startswith("Cloud(50000 points from")


def test_read_binary_ply_equals_numpy(data):
    raw = (data / "patch_20k.ply").read_bytes()
    body = raw[raw.index(b"end_header\n") + len(b"end_header\n"):]
    ref = np.frombuffer(body, dtype="<f8").reshape(-1, 3)
    assert np.array_equal(scanfit.read_cloud(data / "patch_20k.ply").positions, ref)


def test_labels_are_attributes(data):
    cloud = scanfit.read_cloud(data / "vessel_30k.ply")
    labels = cloud.attributes["label"]
    assert labels.shape == (30000,)
    assert sorted(set(labels.astype(int))) == list(range(1, 15))


@pytest.mark.parametrize("name, ascii", [("c.ply", False), ("c.ply", True), ("c.xyz", False), ("c.csv", False)])
def test_write_read_round_trip_is_exact(tmp_path, name, ascii):
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(500, 3)) * 1e3
    attrs = {"u": rng.uniform(size=500), "label": rng.integers(0, 9, 500).astype(float)}
    scanfit.write_cloud(tmp_path / name, pts, attrs, ascii=ascii)
    back = scanfit.read_cloud(tmp_path / name)
    assert np.array_equal(back.positions, pts)
    assert set(back.attributes) == set(attrs)
    for k, v in attrs.items():
        assert np.array_equal(back.attributes[k], v)
    # a Cloud writes its own attributes
    scanfit.write_cloud(tmp_path / ("again_" + name), back)
    again = scanfit.read_cloud(tmp_path / ("again_" + name))
    assert np.array_equal(again.positions, pts)


def test_non_finite_rows_in_files(tmp_path):
    f = tmp_path / "nan.xyz"
    f.write_text("x y z\n0 0 0\n1 nan 2\n3 4 5\n")
    with pytest.raises(scanfit.ScanfitError, match=r"nan.xyz"):
        scanfit.read_cloud(f)
    c = scanfit.read_cloud(f, drop_non_finite=True)
    assert len(c) == 2 and c.dropped_non_finite == 1
    assert np.array_equal(c.positions, [[0, 0, 0], [3, 4, 5]])


def test_cloud_construction_and_info():
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0], [1, 2, 3]], dtype=float)
    c = scanfit.Cloud(pts, {"w": [1, 2, 3, 4]})
    assert np.array_equal(c.attributes["w"], [1, 2, 3, 4])
    assert np.array_equal(c.bounds, [[0, 0, 0], [1, 2, 3]])
    c2 = c.with_attribute("v", np.arange(4.0))
    assert set(c2.attributes) == {"w", "v"} and set(c.attributes) == {"w"}
    info = c.info()
    assert info["points"] == 4 and info["diagonal"] == pytest.approx(np.sqrt(14))
    assert info["attributes"][0] == {"name": "w", "min": 1.0, "max": 4.0}
    assert info["spacing"]["min"] == pytest.approx(1.0)
    with pytest.raises(scanfit.ScanfitError, match="3 values for 4 points"):
        scanfit.Cloud(pts, {"w": [1, 2, 3]})
