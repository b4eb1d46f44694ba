#!/usr/bin/env python3
"""scanfit mba vs. ddemidov/mba, side by side on the same points (BENCHMARKS.md, issue 18).

Purpose
    Fit alone and whole command, at the same final lattice (scanfit `--levels 8 --base 1x1`:
    131 x 131 control values; the peer: grid 2 x 2, 8 levels), with the held-out RMSE, the CPU
    time (user + system of all threads: what a shared machine's load does not inflate) and the
    peak memory of each, for each of scanfit's starts (--starts). Runs alternate (scanfit start
    1, scanfit start 2, ..., peer; again) so all meet the same load; the table gives the best and
    the median of --repeats runs, and the load average. One command gives the whole table.

What it runs (nothing is built here; build both first)
    fit alone, scanfit: target/release/examples/mba_timing POINTS HELDOUT LEVELS START
        (cargo build --release -p scanfit --example mba_timing); prints JSON with fit_s
        (scanfit::mba::mba on the points in memory), fit_cpu_s and heldout_rmse.
    fit alone, peer:    --peer DRIVER POINTS HELDOUT LEVELS zero; your own C++ driver around
        ddemidov/mba's header (see BENCHMARKS.md for what it calls); it must print one JSON
        line with fit_s, fit_cpu_s (std::clock() around the constructor) and heldout_rmse. The
        peer's code and the driver stay out of this repository.
    whole command:      target/release/scanfit mba POINTS --levels 8 --base 1x1 --start START -o OUT.json --quiet
        (the default: it also measures the surface and trims it to the cloud's outline), and
        the same with --measure none --no-trim (the peer's work: read, fit, write), against the
        driver's whole process (read, fit, held-out evaluation), all under /usr/bin/time for
        the wall time, the CPU time and the peak resident memory. Run the script as
        `nice -n -15 python3 ...` (as root) on a shared machine: the children inherit it.

Data: benches/peers/mba_data.py (Franke's function on uniform random points, seed 18).

Command (from the repository root):
    python3 benches/peers/mba_data.py --out /tmp/mbadata
    python3 benches/peers/mba_peer.py --peer /tmp/mbapeer/driver --data /tmp/mbadata
    options: --sizes 1000000 10000000 (default both), --levels 8, --repeats 3 (--repeats-large 1
             above 5 * 10^6 points), --starts fitted mean (scanfit's starts of level 0, default
             both), --fit-only (skip the whole commands), --scanfit PATH, --timing PATH, --json OUT
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


def timed(cmd: list[str]) -> tuple[float, float, float, str]:
    """Wall seconds, CPU seconds (user + system), peak RSS in MB and stdout of cmd under /usr/bin/time."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as t:
        out = subprocess.run(
            ["/usr/bin/time", "-f", "%e %U %S %M", "-o", t.name, *cmd],
            check=True,
            capture_output=True,
            text=True,
        )
        wall, user, system, kb = t.read().split()[-4:]
    return float(wall), float(user) + float(system), int(kb) / 1024.0, out.stdout


def stats(xs: list[float]) -> dict:
    return {"best": min(xs), "median": statistics.median(xs), "all": xs}


def row(a: argparse.Namespace, n: int) -> dict:
    """All runs at n points: per start s_<start>_*, the peer p_*."""
    pts = str(a.data / f"points_{n}.ply")
    held = str(a.data / "heldout.ply")
    lv = str(a.levels)
    r: dict = {}
    add = lambda k, v: r.setdefault(k, []).append(v)  # noqa: E731
    rmse: dict = {}
    load = [os.getloadavg()[0]]
    repeats = a.repeats if n <= 5_000_000 else a.repeats_large
    with tempfile.TemporaryDirectory() as d:
        out = str(Path(d) / "m.json")
        for _ in range(repeats):
            for st in a.starts:
                _, _, m, s = timed([str(a.timing), pts, held, lv, st])
                s = json.loads(s)
                add(f"s_{st}_fit", s["fit_s"])
                add(f"s_{st}_fit_cpu", s["fit_cpu_s"])
                add(f"s_{st}_fit_mem", m)
                rmse[st] = s["heldout_rmse"]
                r["control_points"] = s["control_points"]
            w, c, m, p = timed([str(a.peer), pts, held, lv, "zero"])
            p = json.loads(p)
            add("p_fit", p["fit_s"])
            add("p_fit_cpu", p["fit_cpu_s"])
            add("p_whole", w)
            add("p_whole_cpu", c)
            add("p_mem", m)
            rmse["peer"] = p["heldout_rmse"]
            if not a.fit_only:
                for st in a.starts:
                    cmd = [str(a.scanfit), "mba", pts, "--levels", lv, "--base", "1x1", "--start", st, "-o", out, "--quiet"]
                    # the default (measures and trims), then the peer's work: read, fit, write
                    for tag, extra in (("whole", []), ("equal", ["--measure", "none", "--no-trim"])):
                        w, c, m, _ = timed(cmd + extra)
                        add(f"s_{st}_{tag}", w)
                        add(f"s_{st}_{tag}_cpu", c)
                        add(f"s_{st}_{tag}_mem", m)
            load.append(os.getloadavg()[0])
    res = {k: stats(v) if isinstance(v, list) and k != "control_points" else v for k, v in r.items()}
    res.update(points=n, heldout_rmse=rmse, load_average_1min=load)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--peer", type=Path, required=True, help="the built ddemidov/mba driver")
    ap.add_argument("--data", type=Path, required=True, help="directory written by mba_data.py")
    ap.add_argument("--sizes", type=int, nargs="+", default=[1_000_000, 10_000_000])
    ap.add_argument("--levels", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--repeats-large", type=int, default=1, help="repeats above 5 * 10^6 points")
    ap.add_argument("--starts", choices=["fitted", "mean"], nargs="+", default=["fitted", "mean"])
    ap.add_argument("--fit-only", action="store_true", help="skip the whole commands")
    ap.add_argument("--scanfit", type=Path, default=ROOT / "target/release/scanfit")
    ap.add_argument("--timing", type=Path, default=ROOT / "target/release/examples/mba_timing")
    ap.add_argument("--json", type=Path, help="write the raw results here")
    a = ap.parse_args()
    for exe in (a.peer, a.timing) + (() if a.fit_only else (a.scanfit,)):
        if not exe.exists():
            sys.exit(f"{exe} does not exist; build it first (see this script's docstring)")
    rows = [row(a, n) for n in a.sizes]
    if a.json:
        a.json.write_text(json.dumps(rows, indent=1))
    print("| points | run | scanfit best / median | ddemidov/mba best / median | ratio (peer / scanfit, best) |")
    print("|---|---|---|---|---|")
    for r in rows:
        n = f"10^{len(str(r['points'])) - 1}"
        for st in a.starts:
            runs = [
                (f"fit alone, `{st}`", f"s_{st}_fit", "p_fit", "s"),
                (f"fit alone, `{st}`, CPU time", f"s_{st}_fit_cpu", "p_fit_cpu", "s"),
                (f"peak memory, fit alone, `{st}` (scanfit: the timing example)", f"s_{st}_fit_mem", "p_mem", "MB"),
            ]
            if not a.fit_only:
                runs += [
                    (f"whole command, `{st}`", f"s_{st}_whole", "p_whole", "s"),
                    (f"whole command, `{st}`, CPU time", f"s_{st}_whole_cpu", "p_whole_cpu", "s"),
                    (f"peak memory, whole command, `{st}`", f"s_{st}_whole_mem", "p_mem", "MB"),
                    (f"whole command, the peer's work (`--measure none --no-trim`), `{st}`", f"s_{st}_equal", "p_whole", "s"),
                    (f"the peer's work, `{st}`, CPU time", f"s_{st}_equal_cpu", "p_whole_cpu", "s"),
                    (f"peak memory, the peer's work, `{st}`", f"s_{st}_equal_mem", "p_mem", "MB"),
                ]
            for name, s, p, unit in runs:
                sb, sm, pb, pm = r[s]["best"], r[s]["median"], r[p]["best"], r[p]["median"]
                print(f"| {n} | {name} | {sb:.3g} / {sm:.3g} {unit} | {pb:.3g} / {pm:.3g} {unit} | {pb / sb:.2f} |")
            h, ph = r["heldout_rmse"][st], r["heldout_rmse"]["peer"]
            print(f"| {n} | held-out RMSE (10^5 points), `{st}` | {h:.4e} | {ph:.4e} | {ph / h:.3f} |")
        la = r["load_average_1min"]
        print(f"| {n} | load average (1 min) | {min(la):.1f}-{max(la):.1f} | | |")


if __name__ == "__main__":
    main()
