# Every preset under one memory budget (Table 2 of the variable k-buffer paper as a chart):
# total frame time (top, log scale) and fragment loss (bottom), one bar per scene for each preset.
# usage: gnuplot -c scripts/plots/presets.gnuplot [bench-results/presets.csv [presets.png]]
csv = ARGC >= 1 ? ARG1 : "bench-results/presets.csv"
png = ARGC >= 2 ? ARG2 : "bench-results/presets.png"
load ARG0[1:strstrt(ARG0, "presets.gnuplot") - 1] . "common.gnuplot"
set terminal pngcairo size 1200,900 enhanced font "DejaVu Sans,11" linewidth 1.2
set output png

stats csv using "width" every ::0::0 nooutput
w = int(STATS_max)
stats csv using "scene_index" nooutput
ns = int(STATS_max) + 1
stats csv using "method_index" nooutput
nm = int(STATS_max) + 1
stats csv using "total_ms" nooutput
tmin = STATS_min
tmax = STATS_max
# scene names (one word each) and the budget, for the legend and the title
scenes = ""
do for [s=0:ns-1] {
  stats csv using (column("scene_index") == s ? (name_ = strcol("scene"), 1) : 0) nooutput
  scenes = scenes . " " . name_
}
stats csv using "budget_bytes" nooutput
mib = STATS_max / 1048576.0

colors = "#1f77b4 #ff7f0e #2ca02c #9467bd"
bw = 0.8 / ns
x(s) = column("scene_index") == s ? column("method_index") + (s - (ns - 1) / 2.0) * bw : NaN
failed(s) = column("scene_index") == s && strcol("status") eq "error"

set style fill solid 0.85 border lc rgb "#404040"
set boxwidth bw
set xrange [-0.6:nm - 0.4]
set xtics scale 0 rotate by 30 right
set key outside top center horizontal

set multiplot layout 2, 1
set title sprintf("Every preset under M = %.3g MiB (%dx%d; abuffer has no budget)", \
                  mib, w, w)

set ylabel "total frame time (ms, log scale)"
set logscale y
set yrange [tmin / 3:tmax * 4]
plot csv every ::0::(nm - 1) using "method_index":(NaN):xtic(strcol("method")) notitle, \
     for [s=0:ns-1] csv using (x(s)):"total_ms" with boxes lc rgb word(colors, s + 1) \
         title word(scenes, s + 1), \
     for [s=0:ns-1] csv using (failed(s) ? x(s) : NaN):(tmin / 2.5):("over budget") \
         with labels rotate by 90 left font ",9" tc rgb word(colors, s + 1) notitle

set ylabel "fragments lost (% of generated)"
unset logscale y
set yrange [0:112]
set ytics 0, 20, 100
unset key
unset title
plot csv every ::0::(nm - 1) using "method_index":(NaN):xtic(strcol("method")) notitle, \
     for [s=0:ns-1] csv using (x(s)):"loss_pct" with boxes lc rgb word(colors, s + 1) \
         title word(scenes, s + 1), \
     for [s=0:ns-1] csv using (failed(s) ? x(s) : NaN):(2):("over budget") \
         with labels rotate by 90 left font ",9" tc rgb word(colors, s + 1) notitle, \
     for [s=0:ns-1] csv using (x(s)):"loss_pct":(sprintf("%.0f", column("loss_pct"))) \
         with labels offset 0, 0.6 font ",8" notitle

unset multiplot
