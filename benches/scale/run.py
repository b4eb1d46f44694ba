#!/usr/bin/env python3
"""Whole-command benchmarks of BENCHMARKS.md ("Whole commands at 10^6 and
10^7 points", issue 18 item 3 and issue 14 item 5): wall time, stage split
and peak memory of `scanfit fit` and `scanfit mba` on the inputs of
make_franke.py.

    python3 benches/scale/make_franke.py 1000000 /tmp/franke_1000000.ply
    python3 benches/scale/make_franke.py 1000000 /tmp/franke_uv_1000000.ply --uv
    python3 benches/scale/make_franke.py 10000000 /tmp/franke_10000000.las
    python3 benches/scale/run.py target/release/scanfit 1000000 [--repeat 3] [--only fit|fit_streamed|fit_plane|fit_plane_streamed|fit_fold|fit_fold_streamed|mba|mba_notrim|mba_peerwork|mba_las|mba_las_streamed|mba_laz1|mba_laz1_streamed] [--out-dir /tmp] [-- EXTRA...]

Each command runs `--repeat` times (default 3) under `/usr/bin/time -v`
with SCANFIT_TIMINGS=1 (the CLI then prints each stage's wall time); the
script prints, per command, the median wall time and CPU time, the stage
split of the median run, the largest peak RSS and the bytes per point, and the load
average before and after (the machine is shared). Arguments after `--` are
added to every command (e.g. `--measure full`). When /tmp/franke_N.las
exists, `mba` also runs on it in memory (`mba_las`) and streamed in chunks
of 10^6 points (`mba_las_streamed`, `--chunk-points 1000000`); `mba_notrim` is
`mba` with `--no-trim` (the trim's cost is the difference), `mba_peerwork`
with `--measure none --no-trim` (read, fit, write: what ddemidov/mba's driver
does, `benches/peers/mba_peer.py`). `fit_streamed`
is `fit` read in chunks of 10^6 points; `fit_plane` is `fit` with its
defaults (best-fit plane, distribution knots; untrimmed) on /tmp/franke_N.ply,
`fit_plane_streamed` the same in chunks of 10^6 points (plane and knots as
passes of sums); their input is `make_franke.py N /tmp/franke_xy10_N.ply
--xy-scale 10` (on the unit square the plane is not a height field's).
`fit_fold` is `fit` with its defaults on the unit-square /tmp/franke_N.ply,
whose best-fit plane folds the bumps over, so the fit projects along z
(the fold sample's normals decide), and `fit_fold_streamed` the same in
chunks of 10^6 points (the sample gathered in the covariance pass).
When
/tmp/franke_N_c1.laz exists (the LAS as a compressor-1 LAZ: `cargo run
--release -p scanfit-io --example laz_pointwise -- /tmp/franke_N.las
/tmp/franke_N_c1.laz`), the same two runs on it (`mba_laz1`,
`mba_laz1_streamed`): streamed, its one LAZ chunk of all points is decoded
a requested chunk at a time.
"""
import os
import re
import statistics
import subprocess
import sys


def run_once(cmd):
    env = dict(os.environ, SCANFIT_TIMINGS="1")
    p = subprocess.run(["/usr/bin/time", "-v"] + cmd, env=env,
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", p.stderr).group(1)
    parts = [float(x) for x in wall.split(":")]
    seconds = sum(x * 60 ** (len(parts) - 1 - i) for i, x in enumerate(parts))
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    stages = re.findall(r"^timing: (.*): ([0-9.]+) s$", p.stderr, re.M)
    cpu = sum(float(re.search(rf"{k} time \(seconds\): ([0-9.]+)", p.stderr).group(1))
              for k in ("User", "System"))
    return seconds, rss_kb, stages, cpu


def main():
    args = sys.argv[1:]
    extra = []
    if "--" in args:
        extra = args[args.index("--") + 1:]
        args = args[:args.index("--")]
    if len(args) < 2:
        sys.exit(__doc__)
    binary, n = args[0], int(args[1])
    repeat = int(args[args.index("--repeat") + 1]) if "--repeat" in args else 3
    only = args[args.index("--only") + 1] if "--only" in args else None
    # where the commands write their JSON documents (e.g. a directory of one's own
    # on a shared machine, to compare the surfaces afterwards)
    out = args[args.index("--out-dir") + 1] if "--out-dir" in args else "/tmp"
    commands = {
        "fit": [binary, "fit", f"/tmp/franke_uv_{n}.ply", "--params", "uv-columns",
                "--ctrl", "64x64", "-o", f"{out}/scale_fit.json", "--json", "-q"],
        "mba": [binary, "mba", f"/tmp/franke_{n}.ply", "--levels", "8", "--base", "1x1",
                "-o", f"{out}/scale_mba.json", "--json", "-q"],
    }
    # the same without the trim's alpha shape: its cost is the difference
    commands["mba_notrim"] = commands["mba"] + ["--no-trim"]
    # the peer's work (read, fit, write), as benches/peers/mba_peer.py runs it
    commands["mba_peerwork"] = commands["mba"] + ["--measure", "none", "--no-trim"]
    commands["fit_streamed"] = commands["fit"] + ["--chunk-points", "1000000"]
    commands["fit_plane"] = [binary, "fit", f"/tmp/franke_xy10_{n}.ply", "--ctrl", "64x64",
                             "--no-trim", "-o", f"{out}/scale_fit_plane.json", "--json", "-q"]
    commands["fit_plane_streamed"] = commands["fit_plane"] + ["--chunk-points", "1000000"]
    commands["fit_fold"] = [binary, "fit", f"/tmp/franke_{n}.ply", "--ctrl", "64x64",
                            "--no-trim", "-o", f"{out}/scale_fit_fold.json", "--json", "-q"]
    commands["fit_fold_streamed"] = commands["fit_fold"] + ["--chunk-points", "1000000"]
    # the LAS and its compressor-1 LAZ, in memory and streamed
    for key, path in (("las", f"/tmp/franke_{n}.las"), ("laz1", f"/tmp/franke_{n}_c1.laz")):
        if os.path.exists(path):
            cmd = [binary, "mba", path, "--levels", "8", "--base", "1x1",
                   "-o", f"{out}/scale_mba_{key}.json", "--json", "-q"]
            commands[f"mba_{key}"] = cmd
            commands[f"mba_{key}_streamed"] = cmd + ["--chunk-points", "1000000"]
    for name, cmd in commands.items():
        if only and name != only:
            continue
        cmd = cmd + extra
        load0 = os.getloadavg()[0]
        runs = [run_once(cmd) for _ in range(repeat)]
        load1 = os.getloadavg()[0]
        times = [r[0] for r in runs]
        med = statistics.median(times)
        median_run = min(runs, key=lambda r: abs(r[0] - med))
        peak = max(r[1] for r in runs) * 1024
        print(f"## {name} {n} points: {' '.join(cmd[1:])}")
        cpu = statistics.median(r[3] for r in runs)
        print(f"wall s: {' '.join(f'{t:.2f}' for t in times)}; median {med:.2f}; "
              f"median CPU (user + system) {cpu:.2f} s")
        print(f"peak RSS {peak / 1e6:.0f} MB = {peak / n:.0f} bytes/point; "
              f"load average {load0:.1f} -> {load1:.1f}")
        print("stages of the median run: " + "; ".join(
            f"{s} {float(t):.2f}" for s, t in median_run[2] if s != "start"))
        print()


if __name__ == "__main__":
    main()
