#!/usr/bin/env bash
# `make demo`: compares one method of every family against the exact A-buffer on the built-in demo
# scene (a transparent hairball, max depth complexity > 200) at 256x256 under two memory budgets:
# fixed k (fkb), dynamic k (kplus-dynamic), variable k (vkb), deep (dkb), the optimal k-buffer
# oracle (optimal) and the peer methods engines ship (wboit, mboit, mlab). Writes the images, error
# maps, k-maps, results.json / results.csv and an HTML report.
# About a minute on two cores. MFR_DEMO_OUT overrides the output folder.
set -euo pipefail
mfr=${1:-build/mfr}
out=${MFR_DEMO_OUT:-out/demo}
scene="procedural:hairball"
size=256
# 48 and 96 B/pixel: mboit's 36 B/pixel fit both, the hybrid methods' 20 B/pixel tail leaves them
# k = 1-3 at the first; mlab gets 2 and 4 nodes of 20 B. (The optimal oracle's exact pre-pass is
# what keeps the size at 256x256 for a one-minute demo.)
budgets="3MB,6MB"
methods="fkb,kplus-dynamic,vkb,dkb,optimal,wboit,mboit,mlab"

echo "mfr demo: $scene at ${size}x${size}, methods $methods, budgets $budgets"
"$mfr" compare "$scene" --width $size --height $size --budget "$budgets" --methods "$methods" \
  --out "$out"

report="$(cd "$out" && pwd)/report.html"
echo
echo "  outputs: $out/ (images, *_flip.png, *_kmap.png, results.json, results.csv)"
echo "  report:  file://$report"
