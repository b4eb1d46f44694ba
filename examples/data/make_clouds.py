"""Synthetic scans for the point-cloud examples (numpy only, fixed seed).

    python3 examples/data/make_clouds.py

writes
  patch_20k.ply  a four-sided, doubly curved sheet (a bent panel) of 20 000 points with
                 sampling noise (0.05% of the diagonal), its four sides slightly curved,
                 a round hole near one corner: input for `scanfit cloud boundary` (and the
                 Coons/PDE pipelines).
  blob_30k.ply   a closed, bumpy, egg-shaped body of 30 000 points (y is its long axis):
                 input for `scanfit cloud hpr` and `cloud normals` (and the turntable pipeline).
  bottle_12k.ply a bottle of 12 000 points (body radius 30, shoulder, neck radius 10, height
                 150, closed bottom, open neck) with noise 0.05, its axis tilted away from y
                 to (-0.342, 0.908, 0.243): input for `scanfit turntable` (axis found by PCA).
All are binary little-endian PLY with float64 x, y, z.
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


def bottle(n):
    # area-uniform samples of a surface of revolution r(y), plus the bottom disk
    y = np.linspace(0.0, 150.0, 3001)
    t = np.clip((y - 100.0) / 25.0, 0.0, 1.0)
    r = 30.0 - 20.0 * (3 * t**2 - 2 * t**3) + 1.5 * np.sin(y / 8.0) * (y < 95)
    ds = np.sqrt(1.0 + np.gradient(r, y) ** 2)
    side = r * ds
    side_area = np.trapezoid(2 * np.pi * side, y)
    disk_area = np.pi * r[0] ** 2
    n_disk = int(round(n * disk_area / (side_area + disk_area)))
    cdf = np.cumsum(side)
    cdf /= cdf[-1]
    ys = np.interp(rng.random(n - n_disk), cdf, y)
    rs = np.interp(ys, y, r)
    th = 2 * np.pi * rng.random(n - n_disk)
    body = np.stack([rs * np.cos(th), ys, rs * np.sin(th)], axis=1)
    rd = r[0] * np.sqrt(rng.random(n_disk))
    td = 2 * np.pi * rng.random(n_disk)
    disk = np.stack([rd * np.cos(td), np.zeros(n_disk), rd * np.sin(td)], axis=1)
    p = np.concatenate([body, disk]) + rng.normal(0.0, 0.05, (n, 3))
    # tilt: 20 degrees about z, then 15 degrees about x, and move away from the origin
    a, b = np.radians(20.0), np.radians(15.0)
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    return p @ (rx @ rz).T + np.array([200.0, -40.0, 15.0])


if __name__ == "__main__":
    import os

    here = os.path.dirname(os.path.abspath(__file__))
    write_ply(os.path.join(here, "patch_20k.ply"), patch(20000))
    write_ply(os.path.join(here, "blob_30k.ply"), blob(30000))
    write_ply(os.path.join(here, "bottle_12k.ply"), bottle(12000))
