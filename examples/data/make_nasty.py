"""A deliberately nasty face-like scan for the safety checks (numpy only, fixed seed).

    python3 examples/data/make_nasty.py [N] [OUT]

writes OUT (default examples/data/nasty_face.xyz, N = 6000 points): a face-like
height field, what makes single-patch fits fly off on real range scans:

  * a rounded outline (an ellipse with a chin bulge), so the parameter
    rectangle's corners hold no data;
  * uneven density: half the points crowd the central third (nose and eyes),
    the rest thin out towards the outline (point density falls tenfold);
  * a sparse band: one cheek keeps only 3% of its points;
  * a hole (an eye socket left unscanned);
  * stray points: 0.5% of the points float up to a fifth of the diagonal away;
  * noise of 0.1% of the diagonal.

Units are millimetres (about 160 x 220 x 60). The header is `x y z`.
"""
import sys

import numpy as np

rng = np.random.default_rng(20261202)


def face(n):
    a, b = 80.0, 110.0  # half-width, half-height of the outline
    pts = []
    while sum(len(p) for p in pts) < n:
        m = 4 * n
        # half the draws crowd the centre, the rest spread over the outline
        r = np.where(rng.random(m) < 0.5, 0.35 * np.sqrt(rng.random(m)), np.sqrt(rng.random(m)))
        t = rng.random(m) * 2 * np.pi
        x, y = a * r * np.cos(t), b * r * np.sin(t)
        # chin bulge: the outline is rounder at the bottom
        inside = (x / a) ** 2 + (y / (b * (1.0 + 0.1 * (y < 0)))) ** 2 < 1.0
        eye = (x - 30.0) ** 2 + (y - 25.0) ** 2 < 14.0**2
        cheek = (x < -35.0) & (y < 10.0) & (rng.random(m) > 0.03)
        keep = inside & ~eye & ~cheek
        pts.append(np.column_stack([x[keep], y[keep]]))
    xy = np.concatenate(pts)[:n]
    x, y = xy[:, 0], xy[:, 1]
    rr = (x / a) ** 2 + (y / b) ** 2
    z = 55.0 * np.sqrt(np.clip(1.0 - 0.85 * rr, 0.0, None))  # a dome falling off at the outline
    z += 18.0 * np.exp(-((x / 9.0) ** 2 + ((y + 5.0) / 22.0) ** 2))  # nose
    z -= 6.0 * np.exp(-(((np.abs(x) - 30.0) / 12.0) ** 2 + ((y - 25.0) / 8.0) ** 2))  # eye sockets
    z += 4.0 * np.exp(-((x / 20.0) ** 2 + ((y + 55.0) / 8.0) ** 2))  # lips
    p = np.column_stack([x, y, z])
    diag = np.linalg.norm(p.max(0) - p.min(0))
    p += rng.normal(0.0, 1e-3 * diag, p.shape)
    stray = rng.choice(n, size=max(1, n // 200), replace=False)
    p[stray, 2] += rng.uniform(-0.2, 0.2, len(stray)) * diag
    return p


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 6000
    out = sys.argv[2] if len(sys.argv) > 2 else "examples/data/nasty_face.xyz"
    p = face(n)
    with open(out, "w") as f:
        f.write("x y z\n")
        for q in p:
            f.write(f"{q[0]:.4f} {q[1]:.4f} {q[2]:.4f}\n")


if __name__ == "__main__":
    main()
