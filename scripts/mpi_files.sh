#!/usr/bin/env bash
# Per-rank reading and memory of `cadclash check` under mpirun on a scene of several STEP files
# (docs/results.md, "Distributed checks"): 4 files of 15 boards each (write_board_step ... unshared:
# 255 instances and parts per file, 1,020 in all), 20 m apart, the pairs selected within the boards
# (each file's unused part at its origin would pair across the files). Checked eagerly in one process
# and on 1, 2 and 4 ranks of one thread each; each rank count's JSON report must be byte-identical
# to the one process's. Prints per run the wall time, every rank's line (files read and the seconds
# it took, with a build that reads files where needed) and its peak memory with its isolated readers
# (/usr/bin/time around each rank), and the one process's import time; writes out/mpi-files/<tag>/.
#   bash scripts/mpi_files.sh [BUILD_DIR [CADCLASH [TAG [CHECK_OPTION...]]]]
# (a build with -DCADCLASH_WITH_MPI=ON -DCADCLASH_BUILD_TESTS=ON; CADCLASH: another cadclash binary
# to measure, e.g. one built before files were read where needed; TAG names its results;
# CHECK_OPTIONs are added to every check, e.g. --lazy)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
exe=${2:-$build/tools/cadclash}
tag=${3:-current}
extra=("${@:4}")
out=$root/out/mpi-files
mkdir -p "$out/$tag"
files=()
select=()
for k in 0 1 2 3; do
  f=$out/boards$k.step
  if [ ! -f "$f" ]; then
    "$build/tests/support/write_board_step" "$root/data/external" "$f" 15 $((k * 20000)) unshared >/dev/null
  fi
  files+=("$f")
  select+=("/boards$k.step/board")
done
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none
echo "machine: $(uptime)"
check=("$exe" check "${files[@]}" --select-a "${select[@]}" --select-b "${select[@]}" --threads 1 "${extra[@]}")
/usr/bin/time -f '%e s, peak memory %M KiB' -o "$out/$tag/one.time" "${check[@]}" --json "$out/$tag/one.json" \
  >"$out/$tag/one.out" 2>"$out/$tag/one.err"
echo "$tag one process: $(cat "$out/$tag/one.time"); $(grep -i 'import' "$out/$tag/one.out" | tail -1)"
"${check[@]}" --no-timings --json "$out/$tag/one-nt.json" >/dev/null 2>&1 || true
for n in 1 2 4; do
  rm -f "$out/$tag/np$n.time."*
  start=$(date +%s.%N)
  mpirun --oversubscribe -np "$n" bash -c \
    'exec /usr/bin/time -f "%e s, peak memory with its readers %M KiB" -o "$0.$OMPI_COMM_WORLD_RANK" "$@"' \
    "$out/$tag/np$n.time" "${check[@]}" --no-timings --json "$out/$tag/np$n.json" \
    >"$out/$tag/np$n.out" 2>"$out/$tag/np$n.err"
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  same=$(cmp -s "$out/$tag/one-nt.json" "$out/$tag/np$n.json" && echo identical || echo DIFFERENT)
  echo "$tag $n ranks: $wall s, report $same"
  grep '^rank' "$out/$tag/np$n.err"
  for ((r = 0; r < n; ++r)); do echo "  rank $r: $(cat "$out/$tag/np$n.time.$r")"; done
done
