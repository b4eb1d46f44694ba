"""Samples for patch layouts without hand labels (issue 16), fixed seed.

  part_30k.ply   a CAD-like part with sharp creases and 8 faces, for
                 `scanfit cloud segment` and `scanfit reconstruct --segment`:
                 a 40 x 30 block, a low step (x < 15, top z = 8) and a high part
                 (x > 15) whose top is curved (z = 15 + 4 (1 - ((x - 27.5) / 12.5)^2),
                 radius of curvature about 19.5), flat sides, no fillets.
                 30 000 points, area-uniform, noise sigma 0.02 (3.5e-4 of the
                 diagonal); float32 x, y, z and an int32 `true_face` (0 bottom,
                 1 front y=0, 2 back y=30, 3 left x=0, 4 low top, 5 step riser
                 x=15, 6 curved top, 7 right x=40): the ground truth the tests
                 compare the segmentation with (not a name `reconstruct` reads
                 as labels).
  blob_30k.json  the true volume of the noise-free surface of blob_30k.ply
                 (made by make_clouds.py: radius r(d) times diag(30, 55, 25)
                 plus 8 d_y^2 along y for d_y > 0), by signed tetrahedra over
                 a cube-sphere mesh of 6 x 2 x 400^2 triangles; the 200^2 mesh
                 agrees to the digits printed in `mesh_agreement`.
"""
import json

import numpy as np

rng = np.random.default_rng(20261202)

L, W, XS, ZLOW, ZHIGH, BULGE = 40.0, 30.0, 15.0, 8.0, 15.0, 4.0


def top(x):
    c, h = (XS + L) / 2, (L - XS) / 2
    return ZHIGH + BULGE * (1 - ((x - c) / h) ** 2)


def height(x):
    return np.where(x < XS, ZLOW, top(x))


def rect(n, a, b):
    return rng.random(n) * a, rng.random(n) * b


def profile(n):
    # (x, z) uniform inside the side profile: low step, then the curved top
    out = np.zeros((0, 2))
    while len(out) < n:
        x = rng.random(2 * n) * L
        z = rng.random(2 * n) * (ZHIGH + BULGE)
        ok = z < height(x)
        out = np.vstack([out, np.c_[x[ok], z[ok]]])
    return out[:n]


def curved(n):
    # x with density proportional to arc length of the top, y uniform
    c, h = (XS + L) / 2, (L - XS) / 2
    out = np.zeros(0)
    while len(out) < n:
        x = XS + rng.random(2 * n) * (L - XS)
        slope = -2 * BULGE * (x - c) / h**2
        w = np.sqrt(1 + slope**2) / np.sqrt(1 + (2 * BULGE / h) ** 2)
        out = np.concatenate([out, x[rng.random(2 * n) < w]])
    x = out[:n]
    return np.c_[x, rng.random(n) * W, top(x)]


def part(n):
    c, h = (XS + L) / 2, (L - XS) / 2
    arc = np.trapezoid(np.sqrt(1 + (2 * BULGE * (np.linspace(XS, L, 20001) - c) / h**2) ** 2),
                       np.linspace(XS, L, 20001))
    side = XS * ZLOW + (L - XS) * ZHIGH + (L - XS) * BULGE * 2 / 3
    areas = np.array([L * W, side, side, W * ZLOW, XS * W, W * (ZHIGH - ZLOW), arc * W, W * ZHIGH])
    counts = np.floor(n * areas / areas.sum()).astype(int)
    counts[0] += n - counts.sum()
    faces = []
    x, y = rect(counts[0], L, W)
    faces.append(np.c_[x, y, 0 * x])
    for k, yy in ((1, 0.0), (2, W)):
        xz = profile(counts[k])
        faces.append(np.c_[xz[:, 0], np.full(counts[k], yy), xz[:, 1]])
    y, z = rect(counts[3], W, ZLOW)
    faces.append(np.c_[0 * y, y, z])
    x, y = rect(counts[4], XS, W)
    faces.append(np.c_[x, y, np.full(counts[4], ZLOW)])
    y, z = rect(counts[5], W, ZHIGH - ZLOW)
    faces.append(np.c_[np.full(counts[5], XS), y, ZLOW + z])
    faces.append(curved(counts[6]))
    y, z = rect(counts[7], W, ZHIGH)
    faces.append(np.c_[np.full(counts[7], L), y, z])
    p = np.vstack(faces)
    label = np.repeat(np.arange(8), counts).astype("<i4")
    p = p + rng.normal(0.0, 0.02, p.shape)
    order = rng.permutation(n)
    return p[order], label[order]


def write_ply(path, pts, label):
    rec = np.zeros(len(pts), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("t", "<i4")])
    rec["x"], rec["y"], rec["z"], rec["t"] = pts[:, 0], pts[:, 1], pts[:, 2], label
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment scanfit examples/data/make_layouts.py\nelement vertex {len(pts)}\n"
        "property float x\nproperty float y\nproperty float z\nproperty int true_face\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(rec.tobytes())


def blob_surface(d):
    # make_clouds.py's blob without its noise
    th = np.arctan2(d[..., 2], d[..., 0])
    r = 1.0 + 0.08 * np.sin(5 * th) * (1 - d[..., 1] ** 2) + 0.05 * np.cos(7 * d[..., 1])
    p = d * r[..., None] * np.array([30.0, 55.0, 25.0])
    p[..., 1] += 8.0 * (d[..., 1] > 0) * d[..., 1] ** 2
    return p


def blob_volume(m):
    t = np.linspace(-1.0, 1.0, m + 1)
    a, b = np.meshgrid(t, t, indexing="ij")
    one = np.ones_like(a)
    vol = 0.0
    for axis in range(3):
        for sign in (-1.0, 1.0):
            c = [None, None, None]
            c[axis] = sign * one
            c[(axis + 1) % 3], c[(axis + 2) % 3] = a, b
            d = np.stack(c, axis=-1)
            d /= np.linalg.norm(d, axis=-1)[..., None]
            p = blob_surface(d)
            p00, p10, p11, p01 = p[:-1, :-1], p[1:, :-1], p[1:, 1:], p[:-1, 1:]
            v = np.einsum("...i,...i", p00, np.cross(p10, p11)) + np.einsum(
                "...i,...i", p00, np.cross(p11, p01))
            vol += sign * v.sum() / 6.0
    return abs(vol)


if __name__ == "__main__":
    pts, label = part(30000)
    write_ply("part_30k.ply", pts, label)
    v400, v200 = blob_volume(400), blob_volume(200)
    with open("blob_30k.json", "w") as f:
        json.dump({"true_volume": round(v400, 2), "mesh_agreement": f"{abs(v400 - v200) / v400:.1e}",
                   "made_by": "examples/data/make_layouts.py"}, f, indent=1)
        f.write("\n")
    print(len(pts), "points; blob volume", v400, v200)
