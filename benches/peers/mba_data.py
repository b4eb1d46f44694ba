#!/usr/bin/env python3
"""Data of the MBA peer comparison (BENCHMARKS.md, "MBA against ddemidov/mba").

Franke's function (scanfit::testdata::franke) on uniform random points of the unit square,
written as binary little-endian PLY with double x, y, z:

    points_<n>.ply   n training points, numpy.random.default_rng(seed)
    heldout.ply      10^5 held-out points, default_rng(seed + 1), z the exact function value

Command (from the repository root):
    python3 benches/peers/mba_data.py --out /tmp/mbadata --n 1000000 10000000 --seed 18
Needs numpy (2.4.6 for the recorded run).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np


def franke(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Franke's test function, the same expression as scanfit::testdata::franke."""
    x9, y9 = 9.0 * x, 9.0 * y
    return (
        0.75 * np.exp(-((x9 - 2.0) ** 2 + (y9 - 2.0) ** 2) / 4.0)
        + 0.75 * np.exp(-((x9 + 1.0) ** 2) / 49.0 - (y9 + 1.0) / 10.0)
        + 0.5 * np.exp(-((x9 - 7.0) ** 2 + (y9 - 3.0) ** 2) / 4.0)
        - 0.2 * np.exp(-((x9 - 4.0) ** 2) - (y9 - 7.0) ** 2)
    )


def write(path: Path, n: int, seed: int) -> None:
    """n points drawn from default_rng(seed) (x then y per point), in chunks of 10^6."""
    rng = np.random.default_rng(seed)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment Franke's function, uniform random points, numpy default_rng({seed})\n"
        f"element vertex {n}\nproperty double x\nproperty double y\nproperty double z\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        left = n
        while left > 0:
            k = min(left, 1_000_000)
            xy = rng.random((k, 2))
            xyz = np.column_stack([xy, franke(xy[:, 0], xy[:, 1])])
            f.write(xyz.astype("<f8").tobytes())
            left -= k


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, required=True, help="directory for the PLY files")
    ap.add_argument("--n", type=int, nargs="+", default=[1_000_000, 10_000_000], help="training sizes")
    ap.add_argument("--seed", type=int, default=18)
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    for n in a.n:
        write(a.out / f"points_{n}.ply", n, a.seed)
    write(a.out / "heldout.ply", 100_000, a.seed + 1)


if __name__ == "__main__":
    main()
