# Occupancy-map culling on procedural:hairball, kplus-array k = 8: speed-up over the same method
# without occupancy, and the % of generated fragments rejected, against the bitmap size d.
# usage: gnuplot -c scripts/plots/occupancy.gnuplot [bench-results/occupancy.csv [occupancy.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/occupancy.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/occupancy.png"
load ARG0[1:strstrt(ARG0, "occupancy.gnuplot") - 1] . "common.gnuplot"

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)
stats csv using "kplus_pct" every ::0::0 nooutput
base_kplus = STATS_max  # first row: the baseline without occupancy

set title sprintf("Occupancy-map culling (procedural:hairball, kplus-array k = 8, %dx%d)", w, w)
set xlabel "occupancy bitmap size d (32-bit words per pixel, 32d depth buckets)"
set ylabel "speed-up over kplus-array without occupancy (x)"
set y2label "rejected fragments (% of generated)"
set logscale x 2
set xtics (1, 2, 4, 8, 16, 32, 64)
set xrange [0.8:80]
set yrange [0:*]
set y2range [0:100]
set y2tics 10 nomirror
set ytics nomirror
set key center right
set arrow from graph 0, first 1 to graph 1, first 1 nohead dt 3 lc rgb "#808080"
set arrow from graph 0, second base_kplus to graph 1, second base_kplus nohead dt 4 \
    lc rgb "#ff7f0e"
set label sprintf("without occupancy: %.0f%% rejected by the k^+ test", base_kplus) \
    at graph 0.02, second base_kplus offset 0, 0.7 tc rgb "#ff7f0e"

d(c) = column("d") > 0 ? column("d") : NaN  # row d = 0 is the baseline
plot csv using (d(0)):"speedup_total" axes x1y1 with linespoints lw 2 pt 7 ps 1.2 \
         lc rgb "#1f77b4" title "speed-up: total frame", \
     csv using (d(0)):"speedup_capture" axes x1y1 with linespoints lw 2 pt 5 ps 1.2 \
         lc rgb "#2ca02c" title "speed-up: capture pass", \
     csv using (d(0)):"occupancy_pct" axes x1y2 with linespoints lw 1.5 dt 2 pt 6 \
         lc rgb "#d62728" title "rejected by occupancy (%, right)", \
     csv using (d(0)):"kplus_pct" axes x1y2 with linespoints lw 1.5 dt 2 pt 4 \
         lc rgb "#ff7f0e" title "rejected by k^+ test (%, right)", \
     csv using (d(0)):"rejected_pct" axes x1y2 with linespoints lw 1.5 dt 3 pt 8 \
         lc rgb "#9467bd" title "rejected in total (%, right)"
