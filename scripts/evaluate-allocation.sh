#!/usr/bin/env bash
# One evaluation of the bounded allocations (docs/ALLOCATION_EVAL.md): every real scene in
# ../shared/scenes or --scenes DIR (but the glTF conformance models of khronos-conformance/, which
# test the loader, not transparency) x VIEWS orbit views x relative budgets {10%, 25%, 50%} (each
# method's own words + that share of the exact A-buffer's node bytes) x both compositing rules,
# all bounded k-buffer methods and optimal; writes the mfr compare folders and one summary
# (summary.md, summary.html: per method the geometric mean of the MSE and FLIP ratios to optimal,
# win counts against each other method, and per rule and budget the ratio with the cases that ran
# and were refused; scripts/allocation_summary.py). Under hybrid compositing the per-pixel methods
# run at any share (a pixel without a slot keeps its tail); under kbuffer compositing a share below
# one node per covered pixel is refused.
#
#   scripts/evaluate-allocation.sh [--mfr BIN] [--out DIR] [--size N] [--views V] [--zoom Z]
#                                  [--budgets LIST] [--methods LIST] [--scenes DIR] [--quick]
#   defaults: build/mfr, eval-allocation, 512, 3, 1.0, 10%,25%,50%,
#             fkb,kplus-sb,kplus-dynamic,vkb,vkb-fill,dkb,dkb-fill,dkb-curve,mlab,optimal,
#             ../shared/scenes (searched recursively for .gltf, .glb, .ply and .obj files)
#   --quick: 128x128, one view (a smoke test of the whole pipeline, about a minute)
#
# Scenes are rendered fully transparent (--alpha 0.5), as the papers do. The relative budgets make
# the default framing usable (an absolute 20 MB holds most of these scenes whole). A lower-resolution
# duplicate of a mesh (NAME_res2.ply beside NAME.ply) is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
MFR=build/mfr
OUT=eval-allocation
SIZE=512
VIEWS=3
ZOOM=1.0
BUDGETS=10%,25%,50%
METHODS=fkb,kplus-sb,kplus-dynamic,vkb,vkb-fill,dkb,dkb-fill,dkb-curve,mlab,optimal
SCENES=../shared/scenes
while [ $# -gt 0 ]; do
  case "$1" in
    --mfr) MFR=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --views) VIEWS=$2; shift 2 ;;
    --zoom) ZOOM=$2; shift 2 ;;
    --budgets) BUDGETS=$2; shift 2 ;;
    --methods) METHODS=$2; shift 2 ;;
    --scenes) SCENES=$2; shift 2 ;;
    --quick) SIZE=128; VIEWS=1; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "evaluate-allocation: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [ ! -d "$SCENES" ]; then
  echo "evaluate-allocation: $SCENES not found; nothing to evaluate" >&2
  exit 0
fi
if [ ! -x "$MFR" ]; then
  echo "evaluate-allocation: $MFR is not an executable (build mfr_cli first)" >&2
  exit 1
fi
mapfile -t scenes < <(find "$SCENES" -type f \( -name '*.gltf' -o -name '*.glb' -o -name '*.ply' \
  -o -name '*.obj' \) | grep -v '_res[0-9]*\.ply$' | grep -v '/khronos-conformance/' | sort)
if [ ${#scenes[@]} -eq 0 ]; then
  echo "evaluate-allocation: no scene files under $SCENES" >&2
  exit 1
fi
mkdir -p "$OUT"
start=$(date +%s)
for scene in "${scenes[@]}"; do
  name=$(basename "${scene%.*}")
  for ((v = 0; v < VIEWS; v++)); do
    for composite in kbuffer hybrid; do
      dir="$OUT/${name}_v${v}_${composite}"
      if [ -f "$dir/results.json" ]; then
        echo "evaluate-allocation: $dir (done)"
        continue
      fi
      echo "evaluate-allocation: $dir"
      "$MFR" compare "$scene" --width "$SIZE" --height "$SIZE" --alpha 0.5 \
        --orbit "$VIEWS" --orbit-view "$v" --zoom "$ZOOM" --budget "$BUDGETS" \
        --methods "$METHODS" --composite "$composite" --quiet --out "$dir"
    done
  done
done
seconds=$(($(date +%s) - start))
python3 scripts/allocation_summary.py "$OUT" "$seconds" > /dev/null
echo "evaluate-allocation: $seconds s; summary in $OUT/summary.md and $OUT/summary.html"
