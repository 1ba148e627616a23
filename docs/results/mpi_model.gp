# Model of `cadclash check` on 1-64 MPI nodes (docs/results.md, "Distributed checks"), from the
# per-pair costs measured by scripts/mpi_scaling.sh on this machine (as1 x 556: 24,464 instance
# pairs, 209,056 reported surface pairs, --fast, one thread per rank), scaled to a product with
# 100 x as many pairs (2.4 M instance pairs, 21 M reported pairs). A node has 32 cores (one rank of
# 32 OpenMP threads, assumed to scale perfectly). Regenerate: gnuplot docs/results/mpi_model.gp
set terminal svg size 980,440 font "sans,12"
set output "docs/results/mpi_model.svg"
scale = 100.0
work = 18.5 * scale            # CPU seconds of all parts (0.755 ms per instance pair)
cores = 32.0
imbalance = 1.016              # slowest / mean rank CPU, measured on 2-4 ranks
plan = 0.05 * scale            # every rank plans every pair (2 us per pair)
import_s = 0.14                # every rank imports (instanced .glb; a STEP product is far slower)
merge = 0.20 * scale           # rank 0: decode and merge (1 us per reported pair)
output = 3.9 * scale           # rank 0: table + JSON report (19 us per reported pair)
bytes = 8.68e6 * scale         # results gathered on rank 0 (41 B per reported pair)
gather(n, bw) = n > 1 ? bytes / bw + 1e-5 * log(n) / log(2) : 0
compute(n) = work / (n * cores) * imbalance
total(n, bw) = import_s + plan + compute(n) + gather(n, bw) + merge + output
# The same pairs with 1/100 of the reported surface pairs (sparse contacts: merge, output and the
# gathered bytes shrink 100-fold; the checks cost the same).
sparse(n, bw) = import_s + plan + compute(n) + gather(n, bw) / 100 + (merge + output) / 100
set logscale xy 2
set xrange [1:64]
set xtics (1, 2, 4, 8, 16, 32, 64)
set xlabel "nodes (32 cores each, one rank per node)"
set ylabel "seconds"
set key outside right
set grid
set title "cadclash check under MPI: modelled time of a 2.4 M-pair audit"
plot total(x, 1.25e9) title "total (10 GbE)" lw 3 lc rgb "#1f77b4", \
     sparse(x, 1.25e9) title "total, 1/100 of the contacts (10 GbE)" lw 3 lc rgb "#ff7f0e", \
     total(x, 1.25e8) title "total (1 GbE)" lw 2 dt 2 lc rgb "#1f77b4", \
     compute(x) title "parallel: the ranks' checks" lw 2 lc rgb "#2ca02c", \
     output + merge title "serial: rank 0 merges and writes the report" lw 2 lc rgb "#d62728", \
     gather(x, 1.25e8) title "gather of the results (1 GbE)" lw 2 lc rgb "#9467bd", \
     plan + import_s title "replicated: import + plan" lw 2 lc rgb "#8c564b"
