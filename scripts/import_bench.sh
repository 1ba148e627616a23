#!/usr/bin/env bash
# The import benchmark of docs/results.md ("Import: parallel reading and the cache"): a STEP board
# assembly (the truth tests' board scene, written by write_board_step with a product per instance,
# as exporters that do not find repeated components write them), read by `cadclash check`
#   - one file, cold (no cache);
#   - two files (the board and a copy moved 1 m away, so the files differ and no pair crosses
#     them) one after another (--parallel-files 1) and at once (--parallel-files 2);
#   - one and two files again from a warm --cache.
# Each case runs REPEATS times (default 5), in rounds; the median wall time is reported, with the
# stage times (read, transfer, heal, tessellate, query) of the median run.
#   bash scripts/import_bench.sh [BUILD_DIR] [REPEATS]
# Needs a build with tests (write_board_step is in tests/support). Writes out/import_bench/results.md.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
repeats=${2:-5}
out=$root/out/import_bench
exe=$build/tools/cadclash
mkdir -p "$out"
cd "$root"
for t in cadclash write_board_step; do
  cmake --build "$build" --target "$t" >/dev/null
done
board=$out/board.step
board2=$out/board-moved.step
if [ ! -f "$board" ] || [ ! -f "$board2" ]; then
  "$build/tests/support/write_board_step" data/external "$board" 1 0 unshared
  "$build/tests/support/write_board_step" data/external "$board2" 1 1000 unshared
fi
size_mb=$(awk -v b="$(stat -c %s "$board")" 'BEGIN { printf "%.1f", b / 1e6 }')

# The cases, each run REPEATS times in rounds (every case once per round), so that a change in the
# machine's load falls on all of them alike; per case the median run's wall time and stage line.
names=(one-cold two-serial two-parallel one-warm two-warm)
args_of() {
  case $1 in
    one-cold) echo "$board" ;;
    two-serial) echo "$board $board2 --parallel-files 1" ;;
    two-parallel) echo "$board $board2 --parallel-files 2" ;;
    one-warm) echo "$board --cache $out/cache" ;;
    two-warm) echo "$board $board2 --cache $out/cache" ;;
  esac
}
declare -A times wall stages
load=$(cut -d" " -f1-3 /proc/loadavg)
rm -rf "$out/cache"
"$exe" check "$board" "$board2" --cache "$out/cache" >/dev/null 2>&1 || true  # fill the cache
for ((k = 0; k < repeats; k++)); do
  for name in "${names[@]}"; do
    t0=$(date +%s.%N)
    # shellcheck disable=SC2046  # the paths have no blanks (out/import_bench)
    "$exe" check $(args_of "$name") --json "$out/$name-$k.json" >"$out/$name-$k.txt" 2>"$out/$name-$k.err" || [ $? -eq 3 ]
    t1=$(date +%s.%N)
    times[$name]+="$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }') $k
"
  done
done
for name in "${names[@]}"; do
  median=$(printf '%s' "${times[$name]}" | sort -n | awk -v n="$repeats" 'NR == int((n + 1) / 2)')
  wall[$name]=${median% *}
  stages[$name]=$(grep '^stages:' "$out/$name-${median#* }.txt" | sed 's/^stages: //')
  echo "$name: ${wall[$name]} s ($(printf '%s' "${times[$name]}" | cut -d' ' -f1 | tr '\n' ' '))"
done

# The reports must not depend on how the files were read.
for name in two-parallel two-warm; do
  "$exe" check "$board" "$board2" --no-timings --parallel-files 1 --json "$out/ref.json" >/dev/null 2>&1 || true
  extra=(--parallel-files 2); [ "$name" = two-warm ] && extra=(--cache "$out/cache")
  "$exe" check "$board" "$board2" --no-timings "${extra[@]}" --json "$out/cmp.json" >/dev/null 2>&1 || true
  cmp -s "$out/ref.json" "$out/cmp.json" || { echo "import_bench: $name report differs from the reference" >&2; exit 1; }
done

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }
{
  echo "Board: \`$(basename "$board")\`, $size_mb MB (the truth tests' board scene with a product per instance: 17 instances); the second file is the same assembly moved 1 m along x. $(nproc) cores (load average before the runs: $load), median of $repeats runs, wall time of the whole \`cadclash check\` (default settings: deflection 0.1 mm, certified decisions)."
  echo
  echo "| run | wall s | vs one file cold | stages (summed over files; ms) |"
  echo "|---|---|---|---|"
  for name in one-cold two-serial two-parallel one-warm two-warm; do
    echo "| $name | ${wall[$name]} | $(ratio "${wall[$name]}" "${wall[one-cold]}") | ${stages[$name]} |"
  done
  echo
  echo "Two files at once vs one file: $(ratio "${wall[two-parallel]}" "${wall[one-cold]}")x (goal <= 1.2x); one after another: $(ratio "${wall[two-serial]}" "${wall[one-cold]}")x."
  echo "Warm cache vs cold: one file $(ratio "${wall[one-warm]}" "${wall[one-cold]}"), two files $(ratio "${wall[two-warm]}" "${wall[two-parallel]}") (goal <= 0.10)."
  echo "Reports with --no-timings: byte-identical for --parallel-files 1 and 2 and from the warm cache (checked by this script)."
} | tee "$out/results.md"
