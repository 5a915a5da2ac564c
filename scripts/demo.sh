#!/usr/bin/env bash
# `make demo`: renders the built-in demo scene (a transparent hairball, max depth complexity > 200)
# with the exact A-buffer and with bounded methods under a 40 MB budget, and prints where
# everything went.
set -euo pipefail
mfr=${1:-build/mfr}
out=${MFR_DEMO_OUT:-out/demo}
mkdir -p "$out"
scene="procedural:hairball"
size=1024
common=(--width $size --height $size --quiet)

"$mfr" info "$scene" --width $size --height $size --quiet --json > "$out/scene_info.json"
"$mfr" render "$scene" "${common[@]}" --method abuffer -o "$out/hairball_abuffer.png" \
  --depth-complexity "$out/hairball_depth_complexity.png" --stats-json "$out/hairball_abuffer.json"
for method in fkb kplus-dynamic; do
  for composite in kbuffer hybrid; do
    "$mfr" render "$scene" "${common[@]}" --method $method --budget 40MB --composite $composite \
      -o "$out/hairball_${method}_${composite}.png" --k-map "$out/hairball_${method}_kmap.png" \
      --stats-json "$out/hairball_${method}_${composite}.json"
  done
done

echo "mfr demo: $scene at ${size}x${size}, outputs in $out/"
printf '  %-28s %12s %12s %10s %8s %10s\n' method bytes_used captured lost_% k total_ms
for f in "$out"/hairball_*.json; do
  python3 - "$f" <<'PY' 2>/dev/null || echo "  $(basename "$f")"
import json, sys
d = json.load(open(sys.argv[1]))
name = sys.argv[1].rsplit('/', 1)[-1][len('hairball_'):-len('.json')]
k = f"{d['k_min']}-{d['k_max']}"
print(f"  {name:<28} {d['bytes_used']:>12} {d['fragments_captured']:>12} "
      f"{d['fragments_lost_percent']:>10.2f} {k:>8} {d['total_ms']:>10.1f}")
PY
done
echo "  images: $(cd "$out" && ls *.png | tr '\n' ' ')"
