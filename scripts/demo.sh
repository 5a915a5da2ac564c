#!/usr/bin/env bash
# `make demo`: compares the bounded methods against the exact A-buffer on the built-in demo scene (a
# transparent hairball, max depth complexity > 200) at 1024x1024 under three memory budgets, and
# writes the images, error maps, k-maps, results.json / results.csv and an HTML report.
# About a minute on two cores. MFR_DEMO_OUT overrides the output folder.
set -euo pipefail
mfr=${1:-build/mfr}
out=${MFR_DEMO_OUT:-out/demo}
scene="procedural:hairball"
size=1024
# 20 MB is tight (k = 1-2: the k+-buffer family pays 12 B/pixel of counters, offsets and locks,
# fkb only 4 B), 80 MB keeps ~15 fragments per pixel; the methods order differently across them.
budgets="20MB,40MB,80MB"
methods="fkb,kplus-dynamic,vkb,vkb-fill"

echo "mfr demo: $scene at ${size}x${size}, methods $methods, budgets $budgets"
"$mfr" compare "$scene" --width $size --height $size --budget "$budgets" --methods "$methods" \
  --out "$out"

report="$(cd "$out" && pwd)/report.html"
echo
echo "  outputs: $out/ (images, *_flip.png, *_kmap.png, results.json, results.csv)"
echo "  report:  file://$report"
