"""Sheets for `scanfit reconstruct --layout grid:RxC` (issue 16), fixed seed.

    python3 examples/data/make_sheet.py [DIR]

writes, in DIR (default examples/data):

face_sheet_20k.ply: 20 000 area-uniform
points over a 160 x 220 mm rectangle (four clear corners, one boundary) whose
height is a gentle dome carrying the relief of a face in its middle: a nose,
two eye sockets, a brow and lips, all within |x| < 45, -65 < y < 50. The
detail is local: about a quarter of the sheet carries it, the rest is the
smooth dome (a face scan cropped to a rectangle, a car panel with a badge).
Noise sigma 0.05 mm (1.8e-4 of the diagonal).

panel_20k.ply: 20 000 area-uniform points over a 300 x 200 mm car panel
(a gentle bend and twist) carrying a badge off its centre: an embossed ring
(radius 14 mm, 1.5 mm high, profile width 2.5 mm) with a boss inside, all
within 25 mm of (95, 60). Detail in one place only (about 3% of the panel).
Noise sigma 0.05 mm.

Both: binary little-endian PLY, float32 x, y, z (mm).
"""
import sys

import numpy as np

rng = np.random.default_rng(20261202)

HALF_X, HALF_Y, N, NOISE = 80.0, 110.0, 20_000, 0.05


def height(x, y):
    z = 30.0 - 0.002 * x**2 - 0.0008 * y**2  # the dome
    z += 18.0 * np.exp(-((x / 9.0) ** 2 + ((y + 5.0) / 22.0) ** 2))  # nose
    z -= 6.0 * np.exp(-(((np.abs(x) - 30.0) / 12.0) ** 2 + ((y - 25.0) / 8.0) ** 2))  # eyes
    z += 3.0 * np.exp(-(((np.abs(x) - 28.0) / 18.0) ** 2 + ((y - 42.0) / 5.0) ** 2))  # brow
    z += 4.0 * np.exp(-((x / 20.0) ** 2 + ((y + 55.0) / 8.0) ** 2))  # lips
    return z


def panel(x, y):
    z = 0.0006 * x**2 + 0.0004 * x * y - 0.0002 * y**2  # bend and twist
    r = np.hypot(x - 95.0, y - 60.0)
    z += 1.5 * np.exp(-(((r - 14.0) / 2.5) ** 2))  # the ring
    z += 1.0 * np.exp(-((r / 5.0) ** 2))  # the boss
    return z


def write(out, x, y, z):
    rec = np.zeros(N, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4")])
    rec["x"], rec["y"], rec["z"] = x, y, z
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment scanfit examples/data/make_sheet.py\nelement vertex {N}\n"
        "property float x\nproperty float y\nproperty float z\nend_header\n"
    )
    with open(out, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(rec.tobytes())


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "examples/data"
    x = (2.0 * rng.random(N) - 1.0) * HALF_X
    y = (2.0 * rng.random(N) - 1.0) * HALF_Y
    write(f"{d}/face_sheet_20k.ply", x, y, height(x, y) + rng.normal(0.0, NOISE, N))
    x = (2.0 * rng.random(N) - 1.0) * 150.0
    y = (2.0 * rng.random(N) - 1.0) * 100.0
    write(f"{d}/panel_20k.ply", x, y, panel(x, y) + rng.normal(0.0, NOISE, N))


if __name__ == "__main__":
    main()
