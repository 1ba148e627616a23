#!/usr/bin/env bash
# Per-rank memory and meshing of `cadclash check` under mpirun on a B-rep scene (docs/results.md,
# "Distributed checks"): 59 boards of the truth tests side by side, every instance its own product
# (write_board_step ... unshared: 1,003 instances, 1,003 parts), checked eagerly in one process and on
# 1, 2 and 4 ranks of one thread each; each rank count's JSON report must be byte-identical to the
# one process's. Prints per run the wall time, every rank's line (peak memory, triangles held and
# meshed) and writes out/mpi-part-meshing/<tag>/.
#   bash scripts/mpi_part_meshing.sh [BUILD_DIR [CADCLASH [TAG]]]
# (a build with -DCADCLASH_WITH_MPI=ON -DCADCLASH_BUILD_TESTS=ON; CADCLASH: another cadclash binary
# to measure, e.g. one built before part meshing, TAG names its results)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
exe=${2:-$build/tools/cadclash}
tag=${3:-current}
out=$root/out/mpi-part-meshing
mkdir -p "$out/$tag"
scene=$out/board59u.step
if [ ! -f "$scene" ]; then
  "$build/tests/support/write_board_step" "$root/data/external" "$scene" 59 0 unshared
fi
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none
check=("$exe" check "$scene" --threads 1 --no-timings)
/usr/bin/time -f '%e s, peak memory %M KiB' -o "$out/$tag/one.time" "${check[@]}" --json "$out/$tag/one.json" \
  >"$out/$tag/one.out" 2>"$out/$tag/one.err"
echo "$tag one process: $(cat "$out/$tag/one.time")"
for n in 1 2 4; do
  start=$(date +%s.%N)
  mpirun --oversubscribe -np "$n" "${check[@]}" --json "$out/$tag/np$n.json" >"$out/$tag/np$n.out" 2>"$out/$tag/np$n.err"
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  same=$(cmp -s "$out/$tag/one.json" "$out/$tag/np$n.json" && echo identical || echo DIFFERENT)
  echo "$tag $n ranks: $wall s, report $same"
  grep '^rank' "$out/$tag/np$n.err"
done
