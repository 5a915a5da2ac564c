# Capture and whole-frame throughput per instruction-set path (bench_isa).
# usage: gnuplot -c scripts/plots/isa.gnuplot [bench-results/isa.csv [out.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/isa.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/isa.png"
load ARG0[1:strstrt(ARG0, "isa.gnuplot") - 1] . "common.gnuplot"

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)
stats csv using "threads" every ::0::0 nooutput
threads = int(STATS_max)

set title sprintf("CPU engine per instruction-set path (%dx%d, %d threads)", w, w, threads)
set ylabel "throughput (M fragments/s)"
set style data histograms
set style histogram clustered gap 1.5
set style fill solid 0.85 border lc rgb "#404040"
set boxwidth 0.9
set yrange [0:*]
set terminal pngcairo size 1300,700 enhanced font "DejaVu Sans,11" linewidth 1.2
set output png
set xtics scale 0 font ",8" rotate by -35 left
set key top left
set offsets 0, 0, graph 0.1, 0
set bmargin 11
set rmargin 8

plot csv using "capture_mfrag_s":xtic(strcol("scene") . " " . strcol("method") . " " . \
         strcol("isa")) lc rgb "#1f77b4" title "capture pass", \
     csv using "frame_mfrag_s" lc rgb "#ff7f0e" title "whole frame"
