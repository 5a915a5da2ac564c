# Frame time per pass on the CPU engine and the GL engine, kplus-array k = 8 (bench_engines).
# usage: gnuplot -c scripts/plots/engines.gnuplot [bench-results/engines.csv [out.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/engines.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/engines.png"
load ARG0[1:strstrt(ARG0, "engines.gnuplot") - 1] . "common.gnuplot"

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)

set title sprintf("CPU engine vs GL engine: kplus-array, k = 8, %dx%d (ms per pass, stacked)", w, w)
set ylabel "frame time (ms)"
set style data histograms
set style histogram rowstacked
set style fill solid 0.85 border lc rgb "#404040"
set boxwidth 0.7
set yrange [0:*]
set xtics scale 0
set key top left
set bmargin 5

plot csv using "count_ms":xtic(strcol("scene") . "\n" . strcol("engine")) lc rgb "#1f77b4" title "count", \
     csv using "prefix_sum_ms" lc rgb "#9467bd" title "prefix sum", \
     csv using "capture_ms" lc rgb "#ff7f0e" title "capture", \
     csv using "resolve_ms" lc rgb "#2ca02c" title "resolve", \
     csv using "other_ms" lc rgb "#7f7f7f" title "other"
