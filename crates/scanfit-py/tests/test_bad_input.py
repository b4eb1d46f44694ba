"""Bad arrays and settings raise clear errors, never crash the interpreter.

Policy: float32 and integer arrays (and nested lists) are converted to
float64 (exact) and give the same result as float64; non-contiguous arrays
(strided slices, Fortran order, transposes) are read through their strides
and give the same result; wrong shapes, empty arrays, NaN/inf and bad
settings raise ScanfitError (a ValueError); complex, boolean, string and
object arrays raise TypeError.
"""

import numpy as np
import pytest

import scanfit


def grid(n=20):
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 2, n))
    return np.column_stack([x.ravel(), y.ravel(), (0.3 * np.sin(3 * x) * y).ravel()])


def control_net(points, **kw):
    return scanfit.fit_surface(points, ctrl=(5, 5), **kw)["surface"].control_points


def test_error_is_a_value_error():
    assert issubclass(scanfit.ScanfitError, ValueError)


@pytest.mark.parametrize(
    "bad, shape",
    [
        (np.zeros((10, 2)), r"\(10, 2\)"),
        (np.zeros(30), r"\(30,\)"),
        (np.zeros((2, 5, 3)), r"\(2, 5, 3\)"),
        (np.zeros((0, 3)), r"empty"),
    ],
)
def test_wrong_shape_or_empty(bad, shape):
    with pytest.raises(scanfit.ScanfitError, match=shape):
        scanfit.fit_surface(bad)
    with pytest.raises(scanfit.ScanfitError, match=shape):
        scanfit.Cloud(bad)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_names_the_row(value):
    pts = grid()
    pts[7, 2] = value
    with pytest.raises(scanfit.ScanfitError, match="row 7 has a non-finite coordinate"):
        scanfit.mba(pts)
    with pytest.raises(scanfit.ScanfitError, match="row 7"):
        scanfit.fit_curve(pts[:10])


def test_float32_int_and_lists_are_converted_exactly():
    pts = grid()
    p32 = pts.astype(np.float32)
    assert np.array_equal(control_net(p32), control_net(p32.astype(np.float64)))
    ints = np.round(pts * 100).astype(np.int32)
    assert np.array_equal(control_net(ints), control_net(ints.astype(float)))
    assert np.array_equal(control_net(pts.tolist()), control_net(pts))


def test_non_contiguous_arrays_give_the_contiguous_result():
    pts = grid(30)
    strided = np.repeat(pts, 2, axis=0)[::2]
    assert not strided.flags.c_contiguous
    fortran = np.asfortranarray(pts)
    transposed = np.ascontiguousarray(pts.T).T
    ref = control_net(pts)
    for a in (strided, fortran, transposed):
        assert np.array_equal(control_net(a), ref)
    s = scanfit.fit_surface(pts, ctrl=(5, 5))["surface"]
    uu = np.linspace(0, 1, 12).reshape(3, 4)
    assert np.array_equal(s.evaluate(uu.T, uu.T), s.evaluate(np.ascontiguousarray(uu.T), np.ascontiguousarray(uu.T)))


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((10, 3), dtype=complex),
        np.zeros((10, 3), dtype=bool),
        np.array([["a", "b", "c"]] * 10),
        np.array([[object()] * 3] * 10, dtype=object),
    ],
)
def test_non_numeric_dtypes_are_type_errors(bad):
    with pytest.raises(TypeError, match="real numbers"):
        scanfit.fit_surface(bad)


def test_not_an_array_is_a_type_error():
    with pytest.raises(TypeError):
        scanfit.fit_surface("points.ply")
    with pytest.raises(TypeError):
        scanfit.fit_surface(grid(), ctrl="16x16")


def test_library_errors_carry_the_library_message():
    with pytest.raises(scanfit.ScanfitError, match=r"100 points given, but .* needs at least 256"):
        scanfit.fit_surface(grid(10), ctrl=16, smooth=0)
    with pytest.raises(scanfit.ScanfitError, match="max_levels = 0"):
        scanfit.mba(grid(), levels=0)
    with pytest.raises(scanfit.ScanfitError, match=r"points 1 and 2 coincide"):
        scanfit.fit_curve([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 1, 0], [3, 0, 0]])


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda p: scanfit.fit_surface(p, knots="even"), r'knots = "even" is not one of "distribution", "uniform"'),
        (lambda p: scanfit.mba(p, weight="heavy"), r'weight = "heavy" is not one of'),
        (lambda p: scanfit.boundary(p, criterion="sharp"), r'criterion = "sharp"'),
        (lambda p: scanfit.normals(p, orient="view"), r"needs viewpoint"),
        (lambda p: scanfit.coons(p, pde=(5, 5), ctrl=10), r"exclude each other"),
        (lambda p: scanfit.coons(p, sides=5), r"4 or 3 sides"),
        (lambda p: scanfit.fit_curve(p[:8], smooth=1.0), r"give ctrl"),
        (lambda p: scanfit.fit_surface(p, uv=np.zeros((3, 2))), r"uv must have shape \(400, 2\)"),
    ],
)
def test_bad_settings(call, message):
    with pytest.raises(scanfit.ScanfitError, match=message):
        call(grid())


def test_bad_files(tmp_path):
    with pytest.raises(scanfit.ScanfitError, match="missing.ply"):
        scanfit.read_cloud(tmp_path / "missing.ply")
    bad = tmp_path / "bad.xyz"
    bad.write_text("1 2 3\n4 five 6\n")
    with pytest.raises(scanfit.ScanfitError, match=r"bad.xyz:2"):
        scanfit.read_cloud(bad)
    with pytest.raises(scanfit.ScanfitError, match="unknown point format"):
        scanfit.write_cloud(tmp_path / "out.stl", grid())
    with pytest.raises(scanfit.ScanfitError, match='format = "e57"'):
        scanfit.read_cloud(bad, format="e57")
