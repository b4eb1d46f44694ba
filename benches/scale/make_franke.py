#!/usr/bin/env python3
"""Benchmark inputs for the whole-command measurements of BENCHMARKS.md
("Whole commands at 10^6 and 10^7 points"): Franke's function on uniform
random points in the unit square, written as a binary little-endian PLY.

    python3 benches/scale/make_franke.py N OUT.ply [--uv]

N points, seed 18 (numpy's PCG64); x, y uniform in [0, 1], z = Franke(x, y);
with --uv two more properties u = x and v = y (for `scanfit fit --params
uv-columns`). All properties are float64. The files are big (40 bytes per
point with --uv): write them under /tmp, never commit them.

    python3 benches/scale/make_franke.py N OUT.las

writes the same points as a LAS 1.2 file of point format 0 (20-byte
records, coordinates stored as integers at a scale of 1e-7, one return of
one, class 2), for the LAS rows of "Peak memory of fit and mba".

    python3 benches/scale/make_franke.py N OUT.ply --xy-scale 10

stretches x and y to [0, 10] (z unchanged): a height field flat enough for
the best-fit plane of `scanfit fit`'s default parameters (on the unit square
Franke's heights spread as much as x and y, so the plane's normal is not z).
"""
import sys

import numpy as np


def franke(x, y):
    return (0.75 * np.exp(-((9 * x - 2) ** 2 + (9 * y - 2) ** 2) / 4)
            + 0.75 * np.exp(-((9 * x + 1) ** 2) / 49 - (9 * y + 1) / 10)
            + 0.5 * np.exp(-((9 * x - 7) ** 2 + (9 * y - 3) ** 2) / 4)
            - 0.2 * np.exp(-(9 * x - 4) ** 2 - (9 * y - 7) ** 2))


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    n, out = int(sys.argv[1]), sys.argv[2]
    uv = "--uv" in sys.argv[3:]
    scale = float(sys.argv[sys.argv.index("--xy-scale") + 1]) if "--xy-scale" in sys.argv else 1.0
    rng = np.random.default_rng(18)
    x = rng.random(n)
    y = rng.random(n)
    if out.endswith(".las"):
        write_las(out, x, y, franke(x, y))
        return
    cols = [scale * x, scale * y, franke(x, y)] + ([x, y] if uv else [])
    names = ["x", "y", "z"] + (["u", "v"] if uv else [])
    header = "ply\nformat binary_little_endian 1.0\n"
    header += f"element vertex {n}\n"
    header += "".join(f"property double {c}\n" for c in names)
    header += "end_header\n"
    with open(out, "wb") as f:
        f.write(header.encode("ascii"))
        step = 1_000_000
        for s in range(0, n, step):
            block = np.stack([c[s:s + step] for c in cols], axis=1)
            f.write(block.astype("<f8").tobytes())


def write_las(out, x, y, z):
    """LAS 1.2, point format 0, scale 1e-7, offset 0."""
    import struct
    n, scale = len(x), 1e-7
    h = bytearray(227)
    h[0:4] = b"LASF"
    h[24], h[25] = 1, 2
    h[26:58] = b"scanfit make_franke.py".ljust(32, b"\0")
    struct.pack_into("<HIIBHI", h, 94, 227, 227, 0, 0, 20, n)
    struct.pack_into("<3d3d", h, 131, scale, scale, scale, 0.0, 0.0, 0.0)
    struct.pack_into("<6d", h, 179, x.max(), x.min(), y.max(), y.min(), z.max(), z.min())
    rec = np.dtype([("x", "<i4"), ("y", "<i4"), ("z", "<i4"), ("intensity", "<u2"),
                    ("returns", "u1"), ("class", "u1"), ("angle", "i1"), ("user", "u1"),
                    ("source", "<u2")])
    with open(out, "wb") as f:
        f.write(bytes(h))
        step = 1_000_000
        for s in range(0, n, step):
            r = np.zeros(min(step, n - s), dtype=rec)
            for name, c in (("x", x), ("y", y), ("z", z)):
                r[name] = np.round(c[s:s + step] / scale).astype("<i4")
            r["returns"] = 1 | (1 << 3)
            r["class"] = 2
            f.write(r.tobytes())


if __name__ == "__main__":
    main()
