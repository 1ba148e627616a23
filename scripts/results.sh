#!/usr/bin/env bash
# Regenerates docs/results.md: builds with the benchmarks, runs the accuracy benchmark
# (bench_accuracy), the side-by-side comparison (bench_compare, when built) and the numerical-extremes
# oracle test, then fills docs/results/template.md. Plots go to docs/results/.
#   bash scripts/results.sh [BUILD_DIR]        (default: build; ~5-10 min on 2 cores after the build)
# Raw outputs stay in out/results/ (ground-truth cache in out/results/cache/, reused by later runs).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=$root/out/results
docs=$root/docs/results
cd "$root"
# The tables this page takes from benches it does not run: on a fresh clone, put back from the page
# as it stands (their commit and date with them), so that they are not lost until those benches run.
python3 "$root/scripts/results_kept.py" "$root"

# Configured as scripts/build.sh does, but only the programs this page runs are built: a whole tree
# takes longer than the benchmarks.
echo "results: building $build (bench_accuracy, bench_compare, bench_scale_path, test_triangle_predicates," \
  "bench_triangle_predicates)"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCADCLASH_BUILD_BENCH=ON -DCADCLASH_BUILD_TESTS=ON >/dev/null
else
  cmake -S "$root" -B "$build" -DCADCLASH_BUILD_BENCH=ON -DCADCLASH_BUILD_TESTS=ON >/dev/null
fi
cmake --build "$build" -j "$(nproc)" --target bench_accuracy test_triangle_predicates bench_scale_path \
  bench_triangle_predicates make_board_assembly cadclash
compare_built=no
if cmake --build "$build" --target help | grep -q '^bench_compare:'; then
  if cmake --build "$build" -j "$(nproc)" --target bench_compare; then compare_built=yes
  else echo "results: bench_compare does not build; its section is left out" >&2; fi
fi
mkdir -p "$out" "$docs"
start=$(date +%s)
# The tree as measured: taken before this script writes its plots into docs/.
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
if [ -n "$(git status --porcelain 2>/dev/null)" ]; then commit="$commit (with uncommitted changes)"; fi

echo "results: accuracy against the exact geometry"
"$build/bench/bench_accuracy" --out "$out" | tee "$out/accuracy.log"

if [ "$compare_built" = yes ] && [ -x "$build/bench/bench_compare" ]; then
  echo "results: side-by-side comparison"
  "$build/bench/bench_compare" --data data/external --out "$out" | tee "$out/compare.log"
  compare_status="ran"
else
  echo "results: bench_compare is not built; its section is left out"
  rm -f "$out/compare.md"
  compare_status="skipped"
fi

echo "results: one part moving through a large scene (bench_scale_path)"
"$build/bench/bench_scale_path" --data data/external --out "$out/scale.json" --series "$out/scale_series.dat" \
  >"$out/scale.md"
gnuplot <<GP
set terminal svg size 640,420 font "sans,11"
set output "$out/scale_series.svg"
set logscale xy
set xlabel "instance triangles"
set ylabel "one-shot query (s)"
set key top left
set grid
set fit quiet logfile "/dev/null"
f(x) = a * x
a = 1e-6
fit f(x) "$out/scale_series.dat" using 2:3 via a
plot "$out/scale_series.dat" using 2:3 with linespoints title "1 thread", \
     "$out/scale_series.dat" using 2:4 with linespoints title "2 threads", \
     f(x) with lines dashtype 2 title "linear growth (fit to 1 thread)"
GP

echo "results: numerical extremes (triangle test against the exact oracle)"
"$build/tests/collide/test_triangle_predicates" --gtest_filter='Families/OracleAgreement.*' >"$out/extremes.log" 2>&1 || {
  tail -30 "$out/extremes.log"
  echo "results: the oracle test failed" >&2
  exit 1
}
{
  echo "| family | pairs | intersecting | plain double wrong | filters only wrong | filtered wrong | exact fallbacks |"
  echo "|---|---|---|---|---|---|---|"
  grep '^\[ family   \] |' "$out/extremes.log" | sed 's/^\[ family   \] //'
} >"$out/extremes.md"

echo "results: the triangle families through collide() and Scene::check at every scale"
"$build/tests/collide/test_triangle_predicates" --gtest_filter='Families/PipelineOracle.*' >"$out/pipeline.log" 2>&1 || {
  tail -30 "$out/pipeline.log"
  echo "results: the pipeline oracle test failed" >&2
  exit 1
}
{
  echo "| family | pairs | intersecting | refused (past 2^128) | undecided | wrong |"
  echo "|---|---|---|---|---|---|"
  grep '^\[ pipeline \] |' "$out/pipeline.log" | sed 's/^\[ pipeline \] //'
} >"$out/pipeline.md"

echo "results: triangle predicate speed (bench_triangle_predicates)"
# Time per test of the staged predicate (filters, then CGAL only where they cannot decide) against
# CGAL's exact test on every pair, on the same 4,096 pairs per set.
"$build/bench/bench_triangle_predicates" --benchmark_filter='^(intersect|intersect_exact_only)/' \
  --benchmark_min_time=0.2 --benchmark_format=json >"$out/predicates.json"
python3 - "$out/predicates.json" >"$out/predicates.md" <<'PY'
import json, sys
rows = {}
for b in json.load(open(sys.argv[1]))["benchmarks"]:
    kind, name = b["name"].split("/", 1)
    rows.setdefault(name, {})[kind] = b
print("| pair set (4,096 pairs) | staged: ns per test | exact fallbacks | CGAL exact on every pair: ns per test | speed-up |")
print("|---|---:|---:|---:|---:|")
for name, r in rows.items():
    s, e = r["intersect"], r["intersect_exact_only"]
    ns_s, ns_e = 1e9 * s["per_pair"], 1e9 * e["per_pair"]
    print(f"| {name} | {ns_s:.1f} | {100 * s.get('fallback', 0.0):.2f}% | {ns_e:.1f} | {ns_e / ns_s:.1f}x |")
PY
echo "results: the model-uncertainty band on real-part boards (scripts/uncertainty_bench.sh)"
bash "$root/scripts/uncertainty_bench.sh" "$build" "$out/uncertainty" >"$out/uncertainty.md"
echo "results: certified against --fast on real-part boards (scripts/boards_bench.sh)"
bash "$root/scripts/boards_bench.sh" "$build" "$out/boards" "$out/uncertainty" >"$out/boards.md"
echo "results: continuous motion along paths (scripts/continuous_bench.sh)"
bash "$root/scripts/continuous_bench.sh" "$build" >"$out/continuous.md" ||
  echo "_continuous_bench: the reference found a contact outside cadclash's spans (see above)._" >>"$out/continuous.md"
elapsed=$(( $(date +%s) - start ))

# Plots next to the page; links in the embedded tables point there.
# (mpi_model.svg stays: the MPI section is measured by scripts/mpi_scaling.sh, not by this script)
find "$docs" -maxdepth 1 \( -name '*.svg' -o -name '*.png' \) ! -name 'mpi_model.svg' -delete
for f in "$out"/*.svg "$out"/*.png; do [ -e "$f" ] && cp "$f" "$docs/"; done
relink() { sed -E 's#\]\(([^/():]+\.(svg|png))\)#](results/\1)#g' "$1"; }
# compare.md starts at level 1; under this page's "## Side by side" its headings go two levels down.
demote() { awk '/^```/ { code = !code } !code && /^#/ { $0 = "##" $0 } { print }'; }

cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
# The one-screen summary that opens the page: this run's figures beside their peers'.
python3 "$root/scripts/results_summary.py" "$out" "$(date -u '+%Y-%m-%d %H:%M UTC')" "$commit" \
  "$cpu, $(nproc) vCPUs" >"$out/summary.md"

page=$root/docs/results.md
while IFS= read -r line || [ -n "$line" ]; do
  case "$line" in
    @SUMMARY@) cat "$out/summary.md" ;;
    @MACHINE@)
      echo "- date: $(date -u '+%Y-%m-%d %H:%M UTC')"
      echo "- commit: $commit"
      echo "- CPU: $cpu; nproc: $(nproc)"
      echo "- OS: $(. /etc/os-release && echo "$PRETTY_NAME"); compiler: $(c++ --version | head -1)"
      echo "- benchmarks and oracle run: ${elapsed} s (build excluded)"
      ;;
    @COMPARE@)
      if [ "$compare_status" = ran ] && [ -f "$out/compare.md" ]; then relink "$out/compare.md" | demote
      else echo "_bench_compare was not built in this tree, so this run has no side-by-side section._"; fi
      ;;
    @ACCURACY@) relink "$out/accuracy.md" ;;
    @EXTREMES@) cat "$out/extremes.md" ;;
    @PREDICATES@) cat "$out/predicates.md" ;;
    @PIPELINE_ORACLE@) cat "$out/pipeline.md" ;;
    @SCALE@) cat "$out/scale.md" ;;
    @UNCERTAINTY_BAND@) cat "$out/uncertainty.md" ;;
    @BOARDS@) cat "$out/boards.md" ;;
    @CONTINUOUS@) cat "$out/continuous.md" ;;
    @IMPORT_PEER@)
      # Measured by scripts/import_peer_bench.sh (~20 min), not here: its last table, as it is.
      bench=$root/out/import_peer_bench
      if [ -f "$bench/results.md" ]; then
        relink "$bench/results.md"
        [ -f "$bench/import_time.svg" ] && cp "$bench/import_time.svg" "$docs/"
      else echo "_No run of scripts/import_peer_bench.sh in this tree (out/import_peer_bench/results.md)._"; fi
      ;;
    @IMPORT_CACHE@)
      # Measured by scripts/import_cache_bench.sh (~2 min), not here: its last table, as it is.
      if [ -f "$root/out/import_cache_bench/results.md" ]; then relink "$root/out/import_cache_bench/results.md"
      else echo "_No run of scripts/import_cache_bench.sh in this tree (out/import_cache_bench/results.md)._"; fi
      # The 174 MB board, when it was measured too (IMPORT_CACHE_BENCH_OUT=out/import_cache_bench_174).
      if [ -f "$root/out/import_cache_bench_174/results.md" ]; then echo; relink "$root/out/import_cache_bench_174/results.md"; fi
      ;;
    *) printf '%s\n' "$line" ;;
  esac
done <"$docs/template.md" >"$page"
echo "results: wrote $page (raw outputs in $out)"
