# Recall and precision of every setting against its query time (bench_accuracy writes the data).
#   gnuplot -e "dir='out/results'" bench/plots/accuracy_trade.gp
if (!exists("dir")) dir = "out/results"
set terminal svg size 960,420 dynamic font "sans,11" background rgb "white"
set output dir."/accuracy_trade.svg"
set datafile commentschars "#"
set multiplot layout 1,2 title "Recall and precision against query time (all deflections and tolerances)"
set logscale x
set xlabel "query time (ms, log)"
set yrange [*:1.005]
set offsets 0, 0, 0.01, 0.01
set grid
set key bottom right opaque
modes = "fast certified exact occt-proximity"
set ylabel "recall"
plot for [i=0:3] dir."/accuracy_trade.dat" index i using 1:2 with points pt (i*2+5) ps 1.2 title word(modes, i+1)
set ylabel "precision"
plot for [i=0:3] dir."/accuracy_trade.dat" index i using 1:3 with points pt (i*2+5) ps 1.2 title word(modes, i+1)
unset multiplot
