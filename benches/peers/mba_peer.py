#!/usr/bin/env python3
"""scanfit mba vs. ddemidov/mba, side by side on the same points (BENCHMARKS.md, issue 18).

Purpose
    Fit alone and whole command, at the same final lattice (scanfit `--levels 8 --base 1x1`:
    131 x 131 control values; the peer: grid 2 x 2, 8 levels), with the held-out RMSE and the
    peak memory of each. Runs alternate (scanfit, peer, scanfit, peer, ...) so both meet the same
    load; the table gives the best and the median of --repeats runs and the load average.

What it runs (nothing is built here; build both first)
    fit alone, scanfit: target/release/examples/mba_timing POINTS HELDOUT LEVELS START
        (cargo build --release -p scanfit --example mba_timing); prints JSON with fit_s
        (scanfit::mba::mba on the points in memory) and heldout_rmse.
    fit alone, peer:    --peer DRIVER POINTS HELDOUT LEVELS zero; your own C++ driver around
        ddemidov/mba's header (see BENCHMARKS.md for what it calls); it must print one JSON
        line with fit_s and heldout_rmse. The peer's code and the driver stay out of this
        repository.
    whole command:      target/release/scanfit mba POINTS --levels 8 --base 1x1 --start START -o OUT.json --quiet
        against the driver's whole process (read, fit, held-out evaluation), both under
        /usr/bin/time for the wall time and the peak resident memory.

Data: benches/peers/mba_data.py (Franke's function on uniform random points, seed 18).

Command (from the repository root):
    python3 benches/peers/mba_data.py --out /tmp/mbadata
    python3 benches/peers/mba_peer.py --peer /tmp/mbapeer/driver --data /tmp/mbadata
    options: --sizes 1000000 10000000, --levels 8, --repeats 3, --start fitted|mean (scanfit's
             start of level 0, default fitted), --scanfit PATH, --timing PATH, --json OUT
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def timed(cmd: list[str]) -> tuple[float, float, str]:
    """Wall seconds, peak RSS in MB and stdout of cmd under /usr/bin/time."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as t:
        out = subprocess.run(
            ["/usr/bin/time", "-f", "%e %M", "-o", t.name, *cmd],
            check=True,
            capture_output=True,
            text=True,
        )
        wall, kb = t.read().split()[-2:]
    return float(wall), int(kb) / 1024.0, out.stdout


def stats(xs: list[float]) -> dict:
    return {"best": min(xs), "median": statistics.median(xs), "all": xs}


def row(a: argparse.Namespace, n: int) -> dict:
    pts = str(a.data / f"points_{n}.ply")
    held = str(a.data / "heldout.ply")
    lv = str(a.levels)
    r: dict = {k: [] for k in ("s_fit", "p_fit", "s_fit_mem", "s_whole", "p_whole", "s_mem", "p_mem")}
    load = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory() as d:
        out = str(Path(d) / "m.json")
        for _ in range(a.repeats):
            _, m, s = timed([str(a.timing), pts, held, lv, a.start])
            s = json.loads(s)
            r["s_fit"].append(s["fit_s"])
            r["s_fit_mem"].append(m)
            _, _, p = timed([str(a.peer), pts, held, lv, "zero"])
            p = json.loads(p)
            r["p_fit"].append(p["fit_s"])
            w, m, _ = timed(
                [str(a.scanfit), "mba", pts, "--levels", lv, "--base", "1x1", "--start", a.start, "-o", out, "--quiet"]
            )
            r["s_whole"].append(w)
            r["s_mem"].append(m)
            w, m, _ = timed([str(a.peer), pts, held, lv, "zero"])
            r["p_whole"].append(w)
            r["p_mem"].append(m)
            load.append(os.getloadavg()[0])
    res = {k: stats(v) for k, v in r.items()}
    res["points"] = n
    res["start"] = a.start
    res["s_heldout_rmse"] = s["heldout_rmse"]
    res["p_heldout_rmse"] = p["heldout_rmse"]
    res["control_points"] = s["control_points"]
    res["load_average_1min"] = load
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--peer", type=Path, required=True, help="the built ddemidov/mba driver")
    ap.add_argument("--data", type=Path, required=True, help="directory written by mba_data.py")
    ap.add_argument("--sizes", type=int, nargs="+", default=[1_000_000, 10_000_000])
    ap.add_argument("--levels", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--start", choices=["fitted", "mean"], default="fitted")
    ap.add_argument("--scanfit", type=Path, default=ROOT / "target/release/scanfit")
    ap.add_argument("--timing", type=Path, default=ROOT / "target/release/examples/mba_timing")
    ap.add_argument("--json", type=Path, help="write the raw results here")
    a = ap.parse_args()
    for exe in (a.peer, a.scanfit, a.timing):
        if not exe.exists():
            sys.exit(f"{exe} does not exist; build it first (see this script's docstring)")
    rows = [row(a, n) for n in a.sizes]
    if a.json:
        a.json.write_text(json.dumps(rows, indent=1))
    print("| points | run | scanfit best / median | ddemidov/mba best / median | ratio (peer / scanfit, best) |")
    print("|---|---|---|---|---|")
    for r in rows:
        n = f"10^{len(str(r['points'])) - 1}"
        for name, s, p, unit in (
            ("fit alone", "s_fit", "p_fit", "s"),
            ("whole command", "s_whole", "p_whole", "s"),
            ("peak memory, whole command", "s_mem", "p_mem", "MB"),
            ("peak memory, fit alone (scanfit: the timing example)", "s_fit_mem", "p_mem", "MB"),
        ):
            sb, sm, pb, pm = r[s]["best"], r[s]["median"], r[p]["best"], r[p]["median"]
            print(f"| {n} | {name} | {sb:.3g} / {sm:.3g} {unit} | {pb:.3g} / {pm:.3g} {unit} | {pb / sb:.2f} |")
        print(
            f"| {n} | held-out RMSE (10^5 points) | {r['s_heldout_rmse']:.4e} | {r['p_heldout_rmse']:.4e} | "
            f"{r['p_heldout_rmse'] / r['s_heldout_rmse']:.3f} |"
        )
        la = r["load_average_1min"]
        print(f"| {n} | load average (1 min) | {min(la):.1f}-{max(la):.1f} | | |")


if __name__ == "__main__":
    main()
