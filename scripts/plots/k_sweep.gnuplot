# k sweep: frame time of the k+-buffer with a max-array vs a max-heap store as k grows, n = 128.
# usage: gnuplot -c scripts/plots/k_sweep.gnuplot [bench-results/k_sweep.csv [k_sweep.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/k_sweep.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/k_sweep.png"
load ARG0[1:strstrt(ARG0, "k_sweep.gnuplot") - 1] . "common.gnuplot"

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)
stats csv using "n" every ::0::0 nooutput
n = int(STATS_max)

set title sprintf("k^+-buffer store: max-array vs max-heap " . \
                  "(procedural:layers, n = %d fragments/pixel, pd = 0.5, %dx%d)", n, w, w)
set xlabel "k (fragment slots per pixel)"
set ylabel "time per frame (ms, log scale)"
set logscale x 2
set logscale y
set xtics (4, 8, 12, 16, 24, 32, 48, 64)
set xrange [3.5:72]
set key top left
set arrow from 16, graph 0 to 16, graph 1 nohead dt 3 lc rgb "#808080"
set label "paper: heap wins above k {/Symbol \273} 16" at 16, graph 0.95 offset 0.5, 0 \
    tc rgb "#606060"

array = "#1f77b4"
heap = "#d62728"
plot csv using "k":"array_total_ms" with linespoints lw 2 pt 7 ps 1.2 lc rgb array \
         title "max-array: total", \
     csv using "k":"heap_total_ms" with linespoints lw 2 pt 5 ps 1.2 lc rgb heap \
         title "max-heap: total", \
     csv using "k":"array_capture_ms" with linespoints lw 1.5 dt 2 pt 6 lc rgb array \
         title "max-array: capture pass", \
     csv using "k":"heap_capture_ms" with linespoints lw 1.5 dt 2 pt 4 lc rgb heap \
         title "max-heap: capture pass", \
     csv using "k":"array_resolve_ms" with linespoints lw 1 dt 3 pt 1 lc rgb array \
         title "max-array: resolve pass", \
     csv using "k":"heap_resolve_ms" with linespoints lw 1 dt 3 pt 2 lc rgb heap \
         title "max-heap: resolve pass"
