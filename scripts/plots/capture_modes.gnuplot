# Capture-pass throughput, tile-owned (no locks) vs fragment-parallel (per-pixel spin-locks), k = 8.
# usage: gnuplot -c scripts/plots/capture_modes.gnuplot [bench-results/capture_modes.csv [out.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/capture_modes.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/capture_modes.png"
load ARG0[1:strstrt(ARG0, "capture_modes.gnuplot") - 1] . "common.gnuplot"

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)
stats csv using "threads" every ::0::0 nooutput
threads = int(STATS_max)

set title sprintf("Capture pass: tile-owned vs fragment-parallel (k = 8, %dx%d, %d threads)", \
                  w, w, threads)
set ylabel "capture throughput (M fragments/s)"
set style data histograms
set style histogram clustered gap 1.5
set style fill solid 0.85 border lc rgb "#404040"
set boxwidth 0.9
set yrange [0:*]
set xtics scale 0
set key top left
set offsets 0, 0, graph 0.1, 0
set bmargin 5

label(c) = sprintf("%.1f", column(c))
plot csv using "tile_mfrag_s":xtic(strcol("scene") . "\n" . strcol("method")) \
         lc rgb "#1f77b4" title "tile-owned (no locks)", \
     csv using "parallel_mfrag_s" lc rgb "#ff7f0e" title "fragment-parallel (spin-locks)", \
     csv using ($0 - 0.18):"tile_mfrag_s":(label("tile_mfrag_s")) with labels \
         offset 0, 0.7 font ",9" notitle, \
     csv using ($0 + 0.18):"parallel_mfrag_s":(label("parallel_mfrag_s")) with labels \
         offset 0, 0.7 font ",9" notitle
