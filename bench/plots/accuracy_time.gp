# Import + tessellation time and query time of each mode against the deflection (first tolerance).
#   gnuplot -e "dir='out/results'" bench/plots/accuracy_time.gp
if (!exists("dir")) dir = "out/results"
set terminal svg size 720,440 dynamic font "sans,11" background rgb "white"
set output dir."/accuracy_time.svg"
set datafile commentschars "#"
set title "Time against deflection (first tolerance of the sweep)"
set logscale xy
set xrange [*:*] reverse
set xlabel "linear deflection (mm, log; finer to the right)"
set ylabel "time (ms, log)"
set grid
set key top left
plot dir."/accuracy_time.dat" using 1:2 with linespoints pt 7 title "import + tessellation", \
     "" using 1:3 with linespoints pt 5 title "fast query", \
     "" using 1:4 with linespoints pt 9 title "certified query", \
     "" using 1:5 with linespoints pt 11 title "exact query", \
     "" using 1:6 with linespoints pt 13 title "occt-proximity"
