# A-buffer throughput per pass (M fragments/s) for each scene, with the rasterize + capture goal.
# usage: gnuplot -c scripts/plots/abuffer.gnuplot [bench-results/abuffer.csv [abuffer.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/abuffer.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/abuffer.png"
load ARG0[1:strstrt(ARG0, "abuffer.gnuplot") - 1] . "common.gnuplot"

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)
stats csv using "threads" every ::0::0 nooutput
threads = int(STATS_max)
goal = 100

set title sprintf("A-buffer throughput per pass (%dx%d, %d threads; higher is better)", \
                  w, w, threads)
set ylabel "throughput (M fragments/s, log scale)"
set logscale y
set yrange [1:*]
stats csv using "fragments" nooutput
set xrange [-0.6:STATS_records - 0.4]
set offsets 0, 0, graph 0.15, 0
set bmargin 4
set style fill solid 0.85 border lc rgb "#404040"
set xtics scale 0
set key top right
set arrow from graph 0, first goal to graph 1, first goal nohead lw 1.5 dt 2 lc rgb "#d62728"
set label sprintf("goal: %d M fragments/s for layers, count + capture", goal) \
    at graph 0.99, first goal right offset 0, 0.7 tc rgb "#d62728"

# one cluster per scene (row), one bar per column below
cols = "count_mfrag_s capture_mfrag_s rc_mfrag_s resolve_mfrag_s total_mfrag_s"
titles = "'count pass' 'capture (store) pass' 'rasterize + capture (count + capture)' " . \
         "'resolve (sort + composite)' 'whole render'"
colors = "#9ecae1 #4292c6 #08519c #fd8d3c #bdbdbd"
n = words(cols)
bw = 0.8 / n
x(i) = $0 + (i - (n + 1) / 2.0) * bw
set boxwidth bw
tic(dummy) = sprintf("%s\n%.1fM fragments", strcol("scene"), column("fragments") / 1e6)
height(i) = column(word(cols, i))
plot csv using 0:(NaN):xtic(tic(0)) notitle, \
     for [i=1:n] csv using (x(i)):(height(i)) with boxes lc rgb word(colors, i) \
         title word(titles, i), \
     for [i=1:n] csv using (x(i)):(height(i)):(sprintf("%.0f", height(i))) with labels \
         offset 0, 0.6 font ",9" notitle
