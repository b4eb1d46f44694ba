"""Synthetic scans for the point-cloud examples (numpy only, fixed seed).

    python3 examples/data/make_clouds.py

writes
  patch_20k.ply  a four-sided, doubly curved sheet (a bent panel) of 20 000 points with
                 sampling noise (0.05% of the diagonal), its four sides slightly curved,
                 a round hole near one corner: input for `scanfit cloud boundary` (and the
                 Coons/PDE pipelines).
  blob_30k.ply   a closed, bumpy, egg-shaped body of 30 000 points (y is its long axis):
                 input for `scanfit cloud hpr` and `cloud normals` (and the turntable pipeline).
Both are binary little-endian PLY with float64 x, y, z.
"""
import numpy as np

rng = np.random.default_rng(20261122)


def write_ply(path, pts):
    pts = np.ascontiguousarray(pts, dtype="<f8")
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment scanfit examples/data/make_clouds.py\nelement vertex {len(pts)}\n"
        "property double x\nproperty double y\nproperty double z\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(pts.tobytes())


def patch(n):
    # uniform samples of the parameter square, a hole removed, mapped to a bent panel
    uv = rng.random((int(n * 1.05), 2))
    hole = (uv[:, 0] - 0.75) ** 2 + (uv[:, 1] - 0.7) ** 2 < 0.08 ** 2
    uv = uv[~hole][:n]
    u, v = uv[:, 0], uv[:, 1]
    x = 100.0 * u + 6.0 * np.sin(np.pi * v)          # left/right sides bow outwards
    y = 70.0 * v - 4.0 * np.sin(np.pi * u)           # bottom side bows down
    z = 18.0 * (u - 0.5) ** 2 - 12.0 * (v - 0.5) ** 2 + 5.0 * np.sin(2.0 * u) * v
    p = np.column_stack([x, y, z])
    diag = np.linalg.norm(p.max(0) - p.min(0))
    return p + rng.normal(0.0, 5e-4 * diag, p.shape)


def blob(n):
    # uniform directions, radius modulated by bumps; an egg elongated along y
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    th = np.arctan2(d[:, 2], d[:, 0])
    r = 1.0 + 0.08 * np.sin(5 * th) * (1 - d[:, 1] ** 2) + 0.05 * np.cos(7 * d[:, 1])
    p = d * r[:, None] * np.array([30.0, 55.0, 25.0])
    p[:, 1] += 8.0 * (d[:, 1] > 0) * d[:, 1] ** 2
    return p + rng.normal(0.0, 0.05, p.shape)


if __name__ == "__main__":
    import os

    here = os.path.dirname(os.path.abspath(__file__))
    write_ply(os.path.join(here, "patch_20k.ply"), patch(20000))
    write_ply(os.path.join(here, "blob_30k.ply"), blob(30000))
