"""Segmented synthetic scans for the whole-object (multi-patch) examples and
tests, after the PDE paper's Figs. 9 and 10 (numpy only, fixed seed).

    python3 examples/data/make_multipatch.py

writes
  vessel_30k.ply   a closed pot-like vessel of 30 000 points: a surface of
                   revolution about z (height 100, radius 40 at the bottom
                   bulging to 52 and narrowing to 36 at the top) closed by a
                   flat bottom (z = 0) and a domed lid (rising 8 above
                   z = 100), so that it bounds a solid. Labelled like Fig. 9:
                   the side in 12 subsets, 4 sectors (boundaries at
                   theta = 20, 110, 200, 290 degrees) times 3 bands (z in
                   thirds), labels 1..12 = 1 + 4 * band + sector; the bottom
                   is 13 and the lid 14. Each cap is four-sided: the 4
                   sector boundaries cut its rim into 4 arcs, each shared
                   with one sector's end band, and its 4 corners are where
                   the sector boundaries reach the rim (three patches meet
                   there: two side patches and the cap).
  vessel_30k.json  the vessel's true volume and shape parameters: the
                   volume is computed analytically (pi * integral of r(z)^2
                   for the side, plus pi R^2 d / 2 for the paraboloid dome
                   of the lid) and checked here against an independent fine
                   triangle mesh of the true surface (divergence theorem).
  umbrella_20k.ply an open umbrella-like canopy of 20 000 points: 8 panels
                   between 8 straight-in-plan ribs from the apex (0, 0, 30)
                   to the rib tips at radius 60, each panel sagging between
                   its ribs; labelled like Fig. 10, labels 1..8 by sector.
                   Every panel is three-sided: two ribs (each shared with a
                   neighbour) and its free rim; the apex is one corner
                   shared by all 8 panels and each rib tip is a corner where
                   an interface meets the free boundary.

Noise: every point is displaced by isotropic Gaussian noise of standard
deviation 2e-4 of the bounding-box diagonal (the PDE paper defines its noise
relative to the diagonal, section 5.3). Points are area-uniform on the true
surfaces. Binary little-endian PLY with float64 x, y, z and an int32 `label`
property, the way a segmentation tool (e.g. CloudCompare) exports labels.
"""
import json
import os

import numpy as np

rng = np.random.default_rng(20261201)
HERE = os.path.dirname(os.path.abspath(__file__))

# vessel shape: r(z) = A + B sin(pi z / H) + C z / H, dome height D
H, A, B, C, D = 100.0, 40.0, 14.0, -4.0, 8.0
SECTOR_START = np.radians(20.0)


def write_ply(path, pts, labels, comment):
    rec = np.zeros(len(pts), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("label", "<i4")])
    rec["x"], rec["y"], rec["z"] = pts[:, 0], pts[:, 1], pts[:, 2]
    rec["label"] = labels
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment scanfit examples/data/make_multipatch.py: {comment}\n"
        f"element vertex {len(pts)}\n"
        "property double x\nproperty double y\nproperty double z\nproperty int label\n"
        "end_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(rec.tobytes())


def radius(z):
    return A + B * np.sin(np.pi * z / H) + C * z / H


def dradius(z):
    return B * np.pi / H * np.cos(np.pi * z / H) + C / H


def lid_height(rho):
    # paraboloid dome over the top disk of radius R1 = r(H)
    r1 = radius(H)
    return H + D * (1.0 - (rho / r1) ** 2)


def vessel_volume_analytic():
    # pi * int_0^H (A + B s + C t)^2 dz with s = sin(pi z / H), t = z / H:
    #   int s^2 = H/2, int t^2 = H/3, int s = 2H/pi, int t = H/2, int s t = H/pi
    side = np.pi * (
        A * A * H
        + B * B * H / 2.0
        + C * C * H / 3.0
        + 2.0 * A * B * 2.0 * H / np.pi
        + 2.0 * A * C * H / 2.0
        + 2.0 * B * C * H / np.pi
    )
    r1 = radius(H)
    dome = np.pi * r1 * r1 * D / 2.0
    return side + dome


def vessel_volume_mesh(nz=1500, nt=1500, nr=700):
    """Volume of a fine triangle mesh of the true closed surface (sum of
    signed tetrahedra from the origin), independent of the formula above."""
    th = np.linspace(0.0, 2.0 * np.pi, nt + 1)
    z = np.linspace(0.0, H, nz + 1)
    r = radius(z)
    side = np.stack(
        [r[:, None] * np.cos(th)[None, :], r[:, None] * np.sin(th)[None, :], np.repeat(z[:, None], nt + 1, 1)],
        axis=-1,
    )
    r1 = radius(H)
    rho = np.linspace(r1, 0.0, nr + 1)
    lid = np.stack(
        [rho[:, None] * np.cos(th)[None, :], rho[:, None] * np.sin(th)[None, :], np.repeat(lid_height(rho)[:, None], nt + 1, 1)],
        axis=-1,
    )
    r0 = radius(0.0)
    rho0 = np.linspace(0.0, r0, nr + 1)
    bottom = np.stack(
        [rho0[:, None] * np.cos(th)[None, :], rho0[:, None] * np.sin(th)[None, :], np.zeros((nr + 1, nt + 1))],
        axis=-1,
    )
    vol = 0.0
    for g in (side, lid, bottom):
        # grid (i along the first index, j along theta): outward for these orders
        a, b, c, d = g[:-1, :-1], g[1:, :-1], g[1:, 1:], g[:-1, 1:]
        t1 = np.einsum("...i,...i", a, np.cross(d, c))
        t2 = np.einsum("...i,...i", a, np.cross(c, b))
        vol += (t1.sum() + t2.sum()) / 6.0
    return vol


def sector_of(theta):
    return (np.floor(((theta - SECTOR_START) % (2.0 * np.pi)) / (np.pi / 2.0))).astype(int) % 4


def vessel(n):
    # area of each part: side by the surface-of-revolution element, caps by a fine sum
    z = np.linspace(0.0, H, 20001)
    elem = 2.0 * np.pi * radius(z) * np.sqrt(1.0 + dradius(z) ** 2)
    side_area = np.trapezoid(elem, z)
    r0, r1 = radius(0.0), radius(H)
    bottom_area = np.pi * r0 * r0
    rho = np.linspace(0.0, r1, 20001)
    lid_elem = 2.0 * np.pi * rho * np.sqrt(1.0 + (2.0 * D * rho / (r1 * r1)) ** 2)
    lid_area = np.trapezoid(lid_elem, rho)
    total = side_area + bottom_area + lid_area
    n_bottom = int(round(n * bottom_area / total))
    n_lid = int(round(n * lid_area / total))
    n_side = n - n_bottom - n_lid
    # side: z by the inverse CDF of the area element, theta uniform
    cdf = np.cumsum(elem)
    cdf /= cdf[-1]
    zs = np.interp(rng.random(n_side), cdf, z)
    ts = 2.0 * np.pi * rng.random(n_side)
    rs = radius(zs)
    side = np.column_stack([rs * np.cos(ts), rs * np.sin(ts), zs])
    band = np.minimum((zs / (H / 3.0)).astype(int), 2)
    side_labels = 1 + 4 * band + sector_of(ts)
    # bottom: uniform disk
    rb = r0 * np.sqrt(rng.random(n_bottom))
    tb = 2.0 * np.pi * rng.random(n_bottom)
    bottom = np.column_stack([rb * np.cos(tb), rb * np.sin(tb), np.zeros(n_bottom)])
    # lid: rho by the inverse CDF of the dome's area element
    lcdf = np.cumsum(lid_elem)
    lcdf /= lcdf[-1]
    rl = np.interp(rng.random(n_lid), lcdf, rho)
    tl = 2.0 * np.pi * rng.random(n_lid)
    lid = np.column_stack([rl * np.cos(tl), rl * np.sin(tl), lid_height(rl)])
    pts = np.concatenate([side, bottom, lid])
    labels = np.concatenate([side_labels, np.full(n_bottom, 13), np.full(n_lid, 14)])
    diag = np.linalg.norm(pts.max(0) - pts.min(0))
    pts = pts + rng.normal(0.0, 2e-4 * diag, pts.shape)
    return pts, labels, diag


# umbrella shape
U_N, U_R, U_APEX, U_SAG = 8, 60.0, 30.0, 4.0


def umbrella_point(rho, theta):
    """The canopy: ribs z = APEX (1 - (rho/R)^1.6) along theta_k = 2 pi k / 8,
    sagging by SAG (rho/R) sin(pi phase) between them."""
    phase = (theta % (2.0 * np.pi / U_N)) / (2.0 * np.pi / U_N)
    z = U_APEX * (1.0 - (rho / U_R) ** 1.6) - U_SAG * (rho / U_R) * np.sin(np.pi * phase)
    return np.column_stack([rho * np.cos(theta), rho * np.sin(theta), z])


def umbrella(n):
    # area-uniform by rejection: sample the plan disk, weight by the area element
    pts, labels = [], []
    count = 0
    while count < n:
        m = 4 * n
        rho = U_R * np.sqrt(rng.random(m))
        th = 2.0 * np.pi * rng.random(m)
        # numeric area element |S_rho x S_theta| / rho relative to the plan
        e = 1e-6
        p = umbrella_point(rho, th)
        pr = (umbrella_point(rho + e, th) - umbrella_point(rho - e, th)) / (2 * e)
        pt = (umbrella_point(rho, th + e) - umbrella_point(rho, th - e)) / (2 * e)
        w = np.linalg.norm(np.cross(pr, pt), axis=1) / np.maximum(rho, 1e-12)
        keep = rng.random(m) * 2.0 < w  # w <= 2 for this shape
        pts.append(p[keep])
        labels.append(1 + (np.floor(th[keep] / (2.0 * np.pi / U_N)).astype(int) % U_N))
        count += keep.sum()
    pts = np.concatenate(pts)[:n]
    labels = np.concatenate(labels)[:n]
    diag = np.linalg.norm(pts.max(0) - pts.min(0))
    return pts + rng.normal(0.0, 2e-4 * diag, pts.shape), labels, diag


def main():
    pts, labels, diag = vessel(30000)
    write_ply(os.path.join(HERE, "vessel_30k.ply"), pts, labels, "pot-like vessel, 14 labelled patches")
    v = vessel_volume_analytic()
    vm = vessel_volume_mesh()
    assert abs(v - vm) < 1e-5 * v, (v, vm)
    with open(os.path.join(HERE, "vessel_30k.json"), "w") as f:
        json.dump(
            {
                "file": "vessel_30k.ply",
                "true_volume": v,
                "true_volume_mesh": vm,
                "volume_method": "analytic: pi * int_0^H r(z)^2 dz + pi r(H)^2 D / 2; "
                "checked against a 1500 x 1500 (side) + 700 x 1500 (caps) triangle mesh",
                "shape": {
                    "radius": "r(z) = A + B sin(pi z / H) + C z / H, z in [0, H]",
                    "lid": "z = H + D (1 - (rho / r(H))^2)",
                    "bottom": "z = 0, rho <= r(0)",
                    "H": H,
                    "A": A,
                    "B": B,
                    "C": C,
                    "D": D,
                },
                "labels": {
                    "side": "1 + 4 * band + sector; band = floor(3 z / H), sector = floor(((theta - 20 deg) mod 360) / 90 deg)",
                    "bottom": 13,
                    "lid": 14,
                },
                "noise_sigma": 2e-4 * diag,
                "points": int(len(pts)),
            },
            f,
            indent=2,
        )
        f.write("\n")
    print(f"vessel_30k.ply: {len(pts)} points, diagonal {diag:.3f}, volume {v:.6f} (mesh {vm:.6f})")
    pts, labels, diag = umbrella(20000)
    write_ply(os.path.join(HERE, "umbrella_20k.ply"), pts, labels, "umbrella canopy, 8 three-sided patches")
    print(f"umbrella_20k.ply: {len(pts)} points, diagonal {diag:.3f}")


if __name__ == "__main__":
    main()
