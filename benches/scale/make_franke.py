#!/usr/bin/env python3
"""Benchmark inputs for the whole-command measurements of BENCHMARKS.md
("Whole commands at 10^6 and 10^7 points"): Franke's function on uniform
random points in the unit square, written as a binary little-endian PLY.

    python3 benches/scale/make_franke.py N OUT.ply [--uv]

N points, seed 18 (numpy's PCG64); x, y uniform in [0, 1], z = Franke(x, y);
with --uv two more properties u = x and v = y (for `scanfit fit --params
uv-columns`). All properties are float64. The files are big (40 bytes per
point with --uv): write them under /tmp, never commit them.
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
    rng = np.random.default_rng(18)
    x = rng.random(n)
    y = rng.random(n)
    cols = [x, y, franke(x, y)] + ([x, y] if uv else [])
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


if __name__ == "__main__":
    main()
