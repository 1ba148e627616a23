#!/usr/bin/env bash
# Continuous motion (issue 40, Goals): cadclash's continuous check of paths on as1-tu-203.stp (tunnelling
# parts, the withdraw and unscrew paths with few steps) side by side with the discrete check of the same
# steps, a dense exact B-rep reference (OCCT) and FCL's continuous collision (bench/continuous_bench.cpp).
# Writes a Markdown table and notes on stdout, progress on stderr; timings are printed, never judged.
# Exit 1 only when the reference finds a contact outside cadclash's spans.
#   bash scripts/continuous_bench.sh [BUILD_DIR]
# Environment: CONTINUOUS_BENCH_SAMPLES (reference poses per stretch, default 1000; the issue's 10^5 is
# an opt-in), CONTINUOUS_BENCH_AS1_SAMPLES (the same for withdraw and unscrew, default 25),
# CONTINUOUS_BENCH_REPEATS (timed runs, default 3).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
if [ ! -f "$root/data/external/as1-tu-203.stp" ]; then
  echo "_No data/external/as1-tu-203.stp in this tree (bash scripts/setup.sh): continuous bench skipped._"
  exit 0
fi
bench=$build/bench/continuous_bench
if [ ! -x "$bench" ] || [ "$root/bench/continuous_bench.cpp" -nt "$bench" ] || [ "$root/bench/continuous_reference.cpp" -nt "$bench" ]; then
  if [ ! -f "$build/build.ninja" ] && [ ! -f "$build/Makefile" ]; then
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCADCLASH_BUILD_BENCH=ON >&2
  fi
  cmake --build "$build" --target continuous_bench >&2
fi
"$bench" --data "$root/data/external"
