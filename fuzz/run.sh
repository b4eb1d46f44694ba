#!/usr/bin/env bash
# Coverage-guided fuzzing of every reader and document (cargo-fuzz, libFuzzer).
#
#   fuzz/run.sh [SECONDS_PER_TARGET] [TARGET...]     default: 300 s, every target
#
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
# Each target starts from the seeds in fuzz/corpus/TARGET and the past
# findings in fuzz/regressions/TARGET; new inputs go to fuzz/work/TARGET
# (not committed). -rss_limit_mb=2048 makes an allocation bomb a finding,
# -timeout=10 a hang. One fuzzing process per target, one target at a time
# (no -jobs/-workers forks: the machine's cores are shared). Findings land in fuzz/artifacts/TARGET: minimise one
# with `cargo +nightly fuzz tmin TARGET FILE`, fix the reader, and copy the
# input to fuzz/regressions/TARGET, where `cargo test -p scanfit-io --test
# fuzz_corpus` replays it on stable. A summary line per target (executions,
# coverage) is printed at the end and written to fuzz/work/summary.txt.
# The laz target writes every input to $SCANFIT_FUZZ_LAST when it is set, so
# an input that kills the process before libFuzzer can save it (a stack
# overflow) is still on disk: SCANFIT_FUZZ_LAST=/tmp/last.laz fuzz/run.sh 300 laz
set -euo pipefail
cd "$(dirname "$0")"
secs=${1:-300}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(ply pcd las las_stream laz text stl obj curve_json surface_json model_json)
fi
# no sanitizer: the crates are safe Rust (unsafe_code = "forbid"); debug
# assertions on, so integer overflow is a finding
cargo +nightly fuzz build -s none -a
mkdir -p work
: > work/summary.txt
for t in "${targets[@]}"; do
  mkdir -p "work/$t" "regressions/$t" "artifacts/$t"
  log="work/$t.log"
  status=0
  cargo +nightly fuzz run -s none -a "$t" "work/$t" "corpus/$t" "regressions/$t" -- \
    -max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 -max_len=65536 \
    -print_final_stats=1 >"$log" 2>&1 || status=$?
  # (a crashed run has no final stats: take the last status line)
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || true)
  [ -n "$execs" ] || execs=$(grep -oE '^#[0-9]+' "$log" | tail -1 | tr -d '#' || true)
  cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1 || true)
  line="$t: ${secs}s, ${execs:-?} executions, ${cov:-cov ?}, exit $status"
  echo "$line" | tee -a work/summary.txt
  if [ "$status" -ne 0 ]; then
    echo "  finding: see $log and artifacts/$t/" | tee -a work/summary.txt
  fi
done
