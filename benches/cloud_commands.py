#!/usr/bin/env python3
"""Whole-command timings of the point-cloud commands at 10^6 and 10^7 points (issues 16 and 18).

Purpose
    Times the release CLI end to end (reading, work, writing, as a user runs it) on synthetic
    clouds, with the peak resident memory (`/usr/bin/time -v`) and the load average of the machine
    before each run (the project's machine is 2 cores shared with other builds), and prints the
    median of the runs per command as a Markdown table for BENCHMARKS.md.

Data (numpy, fixed seeds; written once to --dir, not committed):
    box_1e6.ply      10^6 area-uniform points on the surface of a 2 x 1.5 x 1 box, noise +-1e-4
                     (the segmentation bench's cloud: six faces, twelve creases), float64.
    patch_1e6.ply    10^6 points of examples/data/make_clouds.py's bent panel with a hole (same
                     formula, noise 0.05% of the diagonal), float64: `cloud normals`, `coons --pde`.
    blob_1e6.ply     10^6 points of make_clouds.py's egg-shaped bumpy blob, float64: `turntable`,
                     `cloud hpr`.
    sheet_1e7.ply    10^7 points of a jittered terrain-like sheet over [0, 100]^2, float32 x, y, z
                     (a 120 MB binary PLY, as issue 18's `cloud info` row): `cloud info`.
    face_1e6.ply     10^6 points of examples/data/make_sheet.py's face sheet (dome, nose, eyes,
                     brow, lips over 160 x 220 mm, noise sigma 0.05 mm = 0.27 point spacings),
                     float64: `fit` (best-fit plane parameters), for the sampled measures.

Commands timed (outputs go to --dir):
    scanfit cloud segment box_1e6.ply -o seg.ply --quiet
    scanfit cloud info sheet_1e7.ply
    scanfit cloud normals patch_1e6.ply --k 20 --orient view:50,35,1000 -o normals.ply --quiet
    scanfit turntable blob_1e6.ply -o blob.json --quiet
    scanfit cloud hpr blob_1e6.ply --view 0,0,150 -o hpr.ply --quiet   (6 half-depths above the blob)
    scanfit coons patch_1e6.ply --pde 5x5 -o patch.json --quiet
    scanfit turntable blob_1e6.ply -o blob_full.json --quiet --measure full   (turntable_full)
    scanfit fit face_1e6.ply -o face.json --quiet [--measure full]            (face, face_full)

`--quality` prints, after the table, the sampled measures of each command's JSON output (L2
stretch, fold-overs, triangles, sample size): `turntable` against `turntable_full` and `face`
against `face_full` are issue 18's check that a sample agrees with the full computation.

Run (from the repository root, after `cargo build --release -p scanfit-cli`):
    python3 benches/cloud_commands.py --dir /tmp/cloudperf --repeats 3 [--only segment,info]
Takes about 3 minutes with 3 repeats (the first run also writes the inputs, about 1 minute).
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import time

import numpy as np


def write_ply(path, pts, dtype="<f8"):
    pts = np.ascontiguousarray(pts, dtype=dtype)
    kind = "double" if dtype == "<f8" else "float"
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment scanfit benches/cloud_commands.py\nelement vertex {len(pts)}\n"
        f"property {kind} x\nproperty {kind} y\nproperty {kind} z\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(pts.tobytes())


def box(n, rng):
    size = np.array([2.0, 1.5, 1.0])
    areas = np.array([size[1] * size[2], size[0] * size[2], size[0] * size[1]])
    face = rng.choice(6, size=n, p=np.repeat(areas, 2) / (2 * areas.sum()))
    p = rng.random((n, 3)) * size
    axis = face // 2
    side = np.where(face % 2 == 0, 0.0, size[axis])
    p[np.arange(n), axis] = side + 2e-4 * (rng.random(n) - 0.5)
    return p


def patch(n, rng):
    # examples/data/make_clouds.py, patch()
    uv = rng.random((int(n * 1.05), 2))
    hole = (uv[:, 0] - 0.75) ** 2 + (uv[:, 1] - 0.7) ** 2 < 0.08**2
    uv = uv[~hole][:n]
    u, v = uv[:, 0], uv[:, 1]
    x = 100.0 * u + 6.0 * np.sin(np.pi * v)
    y = 70.0 * v - 4.0 * np.sin(np.pi * u)
    z = 18.0 * (u - 0.5) ** 2 - 12.0 * (v - 0.5) ** 2 + 5.0 * np.sin(2.0 * u) * v
    p = np.column_stack([x, y, z])
    diag = np.linalg.norm(p.max(0) - p.min(0))
    return p + rng.normal(0.0, 5e-4 * diag, p.shape)


def blob(n, rng):
    # examples/data/make_clouds.py, blob()
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    th = np.arctan2(d[:, 2], d[:, 0])
    r = 1.0 + 0.08 * np.sin(5 * th) * (1 - d[:, 1] ** 2) + 0.05 * np.cos(7 * d[:, 1])
    p = d * r[:, None] * np.array([30.0, 55.0, 25.0])
    p[:, 1] += 8.0 * (d[:, 1] > 0) * d[:, 1] ** 2
    return p + rng.normal(0.0, 0.05, p.shape)


def face(n, rng):
    # examples/data/make_sheet.py, height() and its noise, at n points
    x = (2.0 * rng.random(n) - 1.0) * 80.0
    y = (2.0 * rng.random(n) - 1.0) * 110.0
    z = 30.0 - 0.002 * x**2 - 0.0008 * y**2
    z += 18.0 * np.exp(-((x / 9.0) ** 2 + ((y + 5.0) / 22.0) ** 2))
    z -= 6.0 * np.exp(-(((np.abs(x) - 30.0) / 12.0) ** 2 + ((y - 25.0) / 8.0) ** 2))
    z += 3.0 * np.exp(-(((np.abs(x) - 28.0) / 18.0) ** 2 + ((y - 42.0) / 5.0) ** 2))
    z += 4.0 * np.exp(-((x / 20.0) ** 2 + ((y + 55.0) / 8.0) ** 2))
    return np.column_stack([x, y, z + rng.normal(0.0, 0.05, n)])


def sheet(n, rng):
    side = int(np.ceil(np.sqrt(n)))
    i = np.arange(n)
    x = ((i % side) + rng.random(n)) * 100.0 / side
    y = ((i // side) + rng.random(n)) * 100.0 / side
    z = 5.0 * np.sin(x * 0.05) * np.cos(y * 0.07) + 0.01 * rng.random(n)
    return np.column_stack([x, y, z])


INPUTS = {
    "box_1e6.ply": (box, 1_000_000, "<f8", 7),
    "patch_1e6.ply": (patch, 1_000_000, "<f8", 20261122),
    "blob_1e6.ply": (blob, 1_000_000, "<f8", 20261122),
    "sheet_1e7.ply": (sheet, 10_000_000, "<f4", 11),
    "face_1e6.ply": (face, 1_000_000, "<f8", 20261202),
}

COMMANDS = {
    "segment": ["cloud", "segment", "box_1e6.ply", "-o", "seg.ply", "--quiet"],
    "info": ["cloud", "info", "sheet_1e7.ply"],
    "normals": [
        "cloud", "normals", "patch_1e6.ply", "--k", "20", "--orient", "view:50,35,1000",
        "-o", "normals.ply", "--quiet",
    ],
    "turntable": ["turntable", "blob_1e6.ply", "-o", "blob.json", "--quiet"],
    "hpr": ["cloud", "hpr", "blob_1e6.ply", "--view", "0,0,150", "-o", "hpr.ply", "--quiet"],
    "coons_pde": ["coons", "patch_1e6.ply", "--pde", "5x5", "-o", "patch.json", "--quiet"],
    "turntable_full": [
        "turntable", "blob_1e6.ply", "-o", "blob_full.json", "--quiet", "--measure", "full",
    ],
    "face": ["fit", "face_1e6.ply", "-o", "face.json", "--quiet"],
    "face_full": ["fit", "face_1e6.ply", "-o", "face_full.json", "--quiet", "--measure", "full"],
}


def quality(d, args):
    """The sampled measures of a command's JSON output (its `-o`), or None."""
    out = args[args.index("-o") + 1]
    if not out.endswith(".json"):
        return None
    import json

    with open(os.path.join(d, out)) as f:
        doc = json.load(f)
    q = doc.get("quality", {})
    return (
        f"L2 stretch {q.get('l2_stretch', 0):.4f}, fold-overs {q.get('fold_overs')} of "
        f"{q.get('triangles')} ({100 * q.get('fold_overs', 0) / max(q.get('triangles', 1), 1):.4f}%), "
        f"measure {json.dumps(doc.get('measure'))}"
    )


def make_inputs(d):
    os.makedirs(d, exist_ok=True)
    for name, (gen, n, dtype, seed) in INPUTS.items():
        path = os.path.join(d, name)
        if not os.path.exists(path):
            print(f"writing {path}", file=sys.stderr)
            write_ply(path, gen(n, np.random.default_rng(seed)), dtype)


def run_once(binary, args, d):
    cmd = ["/usr/bin/time", "-v", binary] + args
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=d, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"{' '.join(args)} failed:\n{p.stderr}")
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    cpu = sum(float(re.search(rf"{k} time \(seconds\): ([0-9.]+)", p.stderr).group(1)) for k in ("User", "System"))
    return wall, rss / 1000.0, load, p.stdout, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", default="/tmp/cloudperf")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", default=",".join(COMMANDS))
    ap.add_argument("--binary", default=os.path.abspath("target/release/scanfit"))
    ap.add_argument("--show", action="store_true", help="print each command's output")
    ap.add_argument("--quality", action="store_true", help="print the sampled measures of each JSON output")
    a = ap.parse_args()
    make_inputs(a.dir)
    measured = []
    print("| command | median wall (s) | runs (s) | CPU user+sys (s) | peak RSS (MB) | load average before |")
    print("|---|---:|---|---|---:|---|")
    for key in a.only.split(","):
        args = COMMANDS[key]
        runs = [run_once(a.binary, args, a.dir) for _ in range(a.repeats)]
        if a.show:
            print(runs[-1][3], file=sys.stderr)
        walls = [r[0] for r in runs]
        print(
            f"| `scanfit {' '.join(args)}` | **{statistics.median(walls):.2f}** | "
            f"{', '.join(f'{w:.2f}' for w in walls)} | {', '.join(f'{r[4]:.2f}' for r in runs)} | "
            f"{max(r[1] for r in runs):.0f} | "
            f"{', '.join(f'{r[2]:.1f}' for r in runs)} |",
            flush=True,
        )
        if a.quality and quality(a.dir, args):
            measured.append(f"{key}: {quality(a.dir, args)}")
    for line in measured:
        print(line)


if __name__ == "__main__":
    main()
