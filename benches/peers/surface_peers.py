#!/usr/bin/env python3
"""scanfit vs. peer tools on one data set: least-squares B-spline surface fit and point inversion.

Purpose
    Side-by-side timing and accuracy of scanfit (Rust, `surface_timing` example) against
      * scipy  -- scipy.interpolate.LSQBivariateSpline (FITPACK surfit), the same bicubic
                  least-squares problem with the same uniform clamped knots; and
      * OpenCASCADE (OCP bindings) -- GeomAPI_ProjectPointOnSurf on a Geom_BSplineSurface built
                  from scanfit's own control points, i.e. point inversion on the identical surface.
    Data (numpy, seed 42): n = 1e6 points, u, v ~ U[0,1), x = 100u, y = 100v,
    z = 10 sin(3u) cos(4v) + 0.01 (U[0,1) - 0.5).  Control net 64 x 64, degree 3 x 3, interior knots
    j/61, j = 1..60 in each direction.

    Caveats that the printed table also states:
      * scanfit fits x, y and z (three right-hand sides) on 2 threads; scipy fits the scalar z only
        (x, y are linear in u, v) on one thread (FITPACK is serial Fortran).
      * OCC is driven from a Python loop (one Perform call per point, single thread, binding overhead
        included; the overhead of the loop itself is measured and reported separately). Only the first
        --occ-points points (default 20,000) are projected; the 1e6 figure is extrapolated linearly
        from the per-point time.
      * scanfit inversion time is for all n points on `threads` cores; its per-core per-point time is
        inversion_seconds * threads / n.

Command (from the repository root, /work/main):
    python3 benches/peers/surface_peers.py
    options: --n N (points, default 1000000), --occ-points K (default 20000),
             --repeats R (best-of-R wall clock for scipy and OCC, default 3),
             --build (force `cargo build --release -p scanfit --example surface_timing`;
                      otherwise it is built only when the binary is missing)
    Takes about 10 minutes on the 2-core machine (one scipy fit of 1e6 points is ~2.5 min).
    Writes benches/peers/surface_peers_results.json next to this script.

Python packages (pip), versions used for the recorded run:
    numpy 2.4.6, scipy 1.17.1, cadquery-ocp 8.0.1.1.0 (import name OCP; OpenCASCADE 7.8/8.x bindings)
    install: pip install numpy scipy cadquery-ocp
"""

from __future__ import annotations

import argparse
import importlib.metadata as md
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
BIN = ROOT / "target" / "release" / "examples" / "surface_timing"
NCTRL = 64
DEG = 3


def version(pkg: str) -> str:
    try:
        return md.version(pkg)
    except md.PackageNotFoundError:
        return "not installed"


def make_data(n: int) -> np.ndarray:
    rng = np.random.default_rng(42)
    u = rng.random(n)
    v = rng.random(n)
    x = 100.0 * u
    y = 100.0 * v
    z = 10.0 * np.sin(3.0 * u) * np.cos(4.0 * v) + 0.01 * (rng.random(n) - 0.5)
    return np.column_stack([u, v, x, y, z])  # (n, 5), columns u v x y z


def run_scanfit(path: Path, build: bool) -> dict:
    if build or not BIN.exists():
        print("building surface_timing with cargo ...", flush=True)
        subprocess.run(
            ["cargo", "build", "--release", "-p", "scanfit", "--example", "surface_timing"],
            cwd=ROOT,
            check=True,
        )
    out = subprocess.run(
        [str(BIN), str(path), str(NCTRL), str(NCTRL)], check=True, capture_output=True, text=True
    )
    return json.loads(out.stdout)


def interior_knots() -> np.ndarray:
    spans = NCTRL - DEG  # 61
    return np.array([j / spans for j in range(1, spans)])  # same floats as scanfit's j as f64 / spans


def run_scipy(u, v, z, repeats: int) -> dict:
    from scipy.interpolate import LSQBivariateSpline

    t = interior_knots()
    best = float("inf")
    spline = None
    caught = []
    for _ in range(repeats):
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            t0 = time.perf_counter()
            spline = LSQBivariateSpline(u, v, z, t, t, kx=DEG, ky=DEG, bbox=[0, 1, 0, 1])
            best = min(best, time.perf_counter() - t0)
        caught += [str(x.message) for x in w]
    # FITPACK coefficient order: c[i * (ny - ky - 1) + j], i along x (= u) -> same as scanfit's i*COUNT_V+j
    coeffs = np.asarray(spline.get_coeffs())
    rmse_z = float(np.sqrt(spline.get_residual() / len(u)))
    return {
        "seconds": best,
        "coeffs": coeffs,
        "rmse_z": rmse_z,
        "warnings": sorted(set(caught)),
        "rank_deficient": any("rank" in m.lower() for m in caught),
    }


def run_occ(ctrl: np.ndarray, pts: np.ndarray, k: int, repeats: int) -> dict:
    from OCP.Geom import Geom_BSplineSurface
    from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
    from OCP.gp import gp_Pnt
    try:  # OCCT 7.x bindings
        from OCP.TColgp import TColgp_Array2OfPnt
        from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
    except ImportError:  # cadquery-ocp 8.x exposes the NCollection typedefs under OCP.collections
        from OCP.collections import Array1_double as TColStd_Array1OfReal
        from OCP.collections import Array1_int as TColStd_Array1OfInteger
        from OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt

    spans = NCTRL - DEG
    poles = TColgp_Array2OfPnt(1, NCTRL, 1, NCTRL)
    for i in range(NCTRL):
        for j in range(NCTRL):
            p = ctrl[i * NCTRL + j]
            poles.SetValue(i + 1, j + 1, gp_Pnt(float(p[0]), float(p[1]), float(p[2])))
    knots = TColStd_Array1OfReal(1, spans + 1)
    mults = TColStd_Array1OfInteger(1, spans + 1)
    for j in range(spans + 1):
        knots.SetValue(j + 1, j / spans)
        mults.SetValue(j + 1, DEG + 1 if j in (0, spans) else 1)
    surface = Geom_BSplineSurface(poles, knots, knots, mults, mults, DEG, DEG)

    sub = [(float(a), float(b), float(c)) for a, b, c in pts[:k]]
    api = "Init(surface, 0, 1, 0, 1) once + Perform(gp_Pnt) per point"
    proj = GeomAPI_ProjectPointOnSurf()
    proj.Init(surface, 0.0, 1.0, 0.0, 1.0)

    best = float("inf")
    res = None
    for _ in range(repeats):
        out = np.full((k, 3), np.nan)
        failed = 0
        t0 = time.perf_counter()
        for idx, (a, b, c) in enumerate(sub):
            proj.Perform(gp_Pnt(a, b, c))
            if proj.NbPoints() > 0:
                uu, vv = proj.LowerDistanceParameters()
                out[idx] = (uu, vv, proj.LowerDistance())
            else:
                failed += 1
        best = min(best, time.perf_counter() - t0)
        res = (out, failed)

    # Python-loop overhead alone: the same loop building gp_Pnt and a tuple, no projection.
    t0 = time.perf_counter()
    dummy = np.full((k, 3), np.nan)
    for idx, (a, b, c) in enumerate(sub):
        q = gp_Pnt(a, b, c)
        dummy[idx] = (a, b, c)
    overhead = time.perf_counter() - t0
    del q, dummy

    out, failed = res
    return {
        "api": api,
        "points": k,
        "seconds": best,
        "per_point": best / k,
        "loop_overhead_per_point": overhead / k,
        "failed": failed,
        "results": out,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--occ-points", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--build", action="store_true")
    args = ap.parse_args()
    n = args.n

    data = make_data(n)
    u, v, x, y, z = data.T
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "surface_points.f64"
        data.astype("<f8").tofile(path)  # row-major: u v x y z per point
        print(f"data: {n} points -> {path} ({path.stat().st_size / 1e6:.0f} MB); running scanfit ...", flush=True)
        sf = run_scanfit(path, args.build)
    threads = int(sf["threads"])
    ctrl = np.asarray(sf["control_points"], dtype=float)
    sf_inv = np.asarray(sf["inversions_first_1000"], dtype=float)
    print(f"scanfit: fit {sf['fit_seconds']:.3f} s, inversion {sf['inversion_seconds']:.3f} s, {threads} threads", flush=True)

    print(f"scipy LSQBivariateSpline, best of {args.repeats} (each ~2.5 min for 1e6 points) ...", flush=True)
    sp = run_scipy(u, v, z, args.repeats)
    coef_diff = float(np.max(np.abs(sp["coeffs"] - ctrl[:, 2])))
    print(f"scipy: {sp['seconds']:.3f} s", flush=True)

    k = min(args.occ_points, n)
    print(f"OCC GeomAPI_ProjectPointOnSurf on the first {k} points, best of {args.repeats} ...", flush=True)
    occ = run_occ(ctrl, data[:, 2:5], k, args.repeats)
    m = min(1000, k, len(sf_inv))
    d = np.abs(occ["results"][:m] - sf_inv[:m])
    occ_du, occ_dv, occ_dd = (float(np.nanmax(d[:, c])) for c in range(3))
    # signed: OCC distance - scanfit distance (positive = scanfit found a closer foot point)
    dd_signed = occ["results"][:m, 2] - sf_inv[:m, 2]

    sf_pp_core = sf["inversion_seconds"] * threads / n
    occ_total = occ["per_point"] * n
    rows = [
        (f"fit {n:.0e} -> 64x64 (scipy LSQBivariateSpline)",
         f"{sf['fit_seconds']:.3f} s (xyz, {threads} thr)", f"{sp['seconds']:.2f} s (z only, 1 thr)",
         f"{sp['seconds'] / sf['fit_seconds']:.0f}x"),
        ("inversion per point, per core (OCC Perform)",
         f"{sf_pp_core * 1e6:.3f} us", f"{occ['per_point'] * 1e6:.2f} us (Python loop)",
         f"{occ['per_point'] / sf_pp_core:.0f}x"),
        (f"inversion {n:.0e} total (OCC extrapolated from {k})",
         f"{sf['inversion_seconds']:.3f} s ({threads} thr)", f"{occ_total:.1f} s (1 thr, extrap.)",
         f"{occ_total / sf['inversion_seconds']:.0f}x"),
        ("z coeffs max |scipy - scanfit|", "", f"{coef_diff:.2e}", ""),
        ("fit RMSE (scanfit 3D / scipy z)", f"{sf['rmse']:.6e}", f"{sp['rmse_z']:.6e}", ""),
        (f"OCC vs scanfit, first {m}: max |du|, |dv|", "", f"{occ_du:.2e}, {occ_dv:.2e}", ""),
        (f"OCC vs scanfit, first {m}: max |d dist|", "", f"{occ_dd:.2e}", ""),
    ]
    w = [max(len(r[c]) for r in rows + [("task", "scanfit", "peer", "peer/scanfit")]) for c in range(4)]
    hdr = ("task", "scanfit", "peer", "peer/scanfit")
    print()
    print(" | ".join(h.ljust(w[c]) for c, h in enumerate(hdr)))
    print("-+-".join("-" * wc for wc in w))
    for r in rows:
        print(" | ".join(r[c].ljust(w[c]) for c in range(4)))
    print()
    print(f"notes: scipy warnings: {sp['warnings'] or 'none'} (rank deficient: {sp['rank_deficient']}); "
          f"OCC api: {occ['api']}; OCC failures: {occ['failed']}/{k}; "
          f"OCC Python-loop overhead alone {occ['loop_overhead_per_point'] * 1e6:.2f} us/point; "
          f"scanfit unconverged: {sf.get('unconverged')}, mean iterations {sf.get('mean_iterations', float('nan')):.2f}; "
          f"OCC dist - scanfit dist: min {np.nanmin(dd_signed):.2e}, max {np.nanmax(dd_signed):.2e}")

    results = {
        "command": "python3 benches/peers/surface_peers.py" + (" " + " ".join(sys.argv[1:]) if sys.argv[1:] else ""),
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version()},
        "versions": {p: version(p) for p in ("numpy", "scipy", "cadquery-ocp")},
        "data": {"n": n, "seed": 42, "ctrl": [NCTRL, NCTRL], "degree": [DEG, DEG]},
        "scanfit": {k2: sf[k2] for k2 in ("threads", "fit_seconds", "inversion_seconds", "rmse", "unconverged", "mean_iterations") if k2 in sf}
        | {"inversion_per_point_per_core_seconds": sf_pp_core, "fits": "x, y, z"},
        "scipy": {"seconds_best": sp["seconds"], "repeats": args.repeats, "fits": "z only", "threads": 1,
                  "rmse_z": sp["rmse_z"], "warnings": sp["warnings"], "rank_deficient": sp["rank_deficient"],
                  "z_coeff_max_abs_diff_vs_scanfit": coef_diff,
                  "ratio_vs_scanfit_fit": sp["seconds"] / sf["fit_seconds"]},
        "occ": {"api": occ["api"], "points_timed": k, "repeats": args.repeats, "seconds_best": occ["seconds"],
                "per_point_seconds": occ["per_point"], "loop_overhead_per_point_seconds": occ["loop_overhead_per_point"],
                "extrapolated_seconds_for_n": occ_total, "extrapolated": True, "threads": 1,
                "failed": occ["failed"],
                "ratio_per_point_vs_scanfit_per_core": occ["per_point"] / sf_pp_core,
                "ratio_total_vs_scanfit_total": occ_total / sf["inversion_seconds"],
                "compare_first": m, "max_abs_du": occ_du, "max_abs_dv": occ_dv, "max_abs_ddist": occ_dd,
                "ddist_signed_min": float(np.nanmin(dd_signed)), "ddist_signed_max": float(np.nanmax(dd_signed))},
    }
    out = HERE / "surface_peers_results.json"
    out.write_text(json.dumps(results, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
