# Shared settings of the benchmark plots (loaded by every scripts/plots/*.gnuplot).
# Each plot script reads `csv` and writes `png` (its arguments 1 and 2, see scripts/bench.sh).
set datafile separator comma
set datafile missing ""
set datafile columnheaders  # the first row names the columns (plots use the names)
set terminal pngcairo size 1100,650 enhanced font "DejaVu Sans,11" linewidth 1.2
set output png
set grid ytics lc rgb "#d0d0d0"
set border 3
set tics nomirror
set key opaque box lc rgb "#c0c0c0"
