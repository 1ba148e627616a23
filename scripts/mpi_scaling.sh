#!/usr/bin/env bash
# Strong scaling of `cadclash check` under mpirun on this machine (docs/results.md, "Distributed
# checks"): a generated scene of 556 copies of as1 (10,008 instances, 1.35e7 triangles over instances)
# checked in one process and on 1-4 ranks of one thread each; every rank count's JSON report must be
# byte-identical to the one process's. Writes out/mpi-scaling/ (scaling.tsv, each run's stderr).
#   bash scripts/mpi_scaling.sh [BUILD_DIR]     (a build with -DCADCLASH_WITH_MPI=ON -DCADCLASH_BUILD_BENCH=ON)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=$root/out/mpi-scaling
mkdir -p "$out"
scene=$out/as1x556.glb
if [ ! -f "$scene" ]; then
  "$build/bench/make_grid_scene" "$root/data/external/as1-tu-203.stp" 556 0.002 "$scene" | tee "$out/scene.txt"
fi
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none
check=("$build/tools/cadclash" check "$scene" --fast --threads 1 --no-timings)
printf 'ranks\twall_s\tslowest_rank_s\tmean_rank_s\tslowest_rank_cpu_s\tmean_rank_cpu_s\tcpu_imbalance\tplan_s\tmerge_s\tresult_bytes\tpeak_rank_mib\tidentical\n' >"$out/scaling.tsv"
# One process: wall, user+system CPU and peak memory of the whole run (import and output included).
/usr/bin/time -f '%e %U %S %M' -o "$out/one.time" "${check[@]}" --json "$out/one.json" >"$out/one.out" 2>"$out/one.err"
read -r wall user sys peak <"$out/one.time"
printf '0\t%.2f\t\t\t%.2f\t\t\t\t\t\t%.1f\t\n' "$wall" "$(echo "$user + $sys" | bc)" "$(echo "$peak / 1024" | bc -l)" >>"$out/scaling.tsv"
for n in 1 2 3 4; do
  start=$(date +%s.%N)
  mpirun --oversubscribe -np "$n" "${check[@]}" --json "$out/np$n.json" >"$out/np$n.out" 2>"$out/np$n.err"
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  same=$(cmp -s "$out/one.json" "$out/np$n.json" && echo yes || echo NO)
  # "rank r of N: P instance pairs (estimated cost C), T triangles, S s (CPU U s; plan Q s), peak memory M MiB, results K KiB"
  awk -v n="$n" -v wall="$wall" -v same="$same" '
    /^rank [0-9]+ of / { s = $13 + 0; u = $16 + 0
                         for (i = 1; i <= NF; ++i) { if ($i == "plan") plan = $(i+1); if ($i == "memory") m = $(i+1); if ($i == "results") kb = $(i+1) }
                         sum += s; if (s > slow) slow = s; usum += u; if (u > uslow) uslow = u
                         if (m > peak) peak = m; bytes += kb * 1024; if (plan > pl) pl = plan; ++k }
    /^load imbalance/ { merge = $(NF-1) }
    END { printf "%d\t%.2f\t%.3f\t%.3f\t%.3f\t%.3f\t%.3f\t%.3f\t%s\t%d\t%.1f\t%s\n", n, wall, slow, sum / k, uslow, usum / k,
                 uslow / (usum / k), pl, merge, bytes, peak, same }' \
    "$out/np$n.err" >>"$out/scaling.tsv"
done
column -t -s $'\t' "$out/scaling.tsv"
