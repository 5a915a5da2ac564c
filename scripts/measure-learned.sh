#!/usr/bin/env bash
# The learned allocations against the optimal k-buffer on the real scenes of ../shared/scenes (never
# seen in training; issue 14 sec. 2-4): mfr compare at SIZE x SIZE, --alpha 0.5 --zoom 1.6, orbit
# view 0 of 3, budgets leaving 25% and 50% of the exact A-buffer's node memory (the optimal
# method's per-pixel words plus that share of n_total x 8 bytes), both compositing rules; methods
# fkb, dkb, dkb-fill, dkb-curve, optimal, and dkb with OLD_MODEL when given (an .mfrnn of the
# hybrid rule, relabelled for kbuffer by this script so that the rule check lets it run there too,
# as the old single model did). Prints the geometric mean of MSE / optimal per method and rule.
#
#   scripts/measure-learned.sh [MFR_BINARY] [OUT_DIR] [SIZE] [OLD_MODEL]
#       defaults: build/mfr, build/measure-learned, 512, none
set -euo pipefail
cd "$(dirname "$0")/.."
MFR=${1:-build/mfr}
OUT=${2:-build/measure-learned}
SIZE=${3:-512}
OLD=${4:-}
SCENES=../shared/scenes
if [ ! -d "$SCENES" ]; then
  echo "measure-learned: $SCENES not found; nothing to measure" >&2
  exit 0
fi
scenes=(
  khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf
  khronos/StainedGlassLamp/glTF-JPG-PNG/StainedGlassLamp.gltf
  khronos/GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb
  khronos/TransmissionTest/glTF-Binary/TransmissionTest.glb
  stanford/bunny/bun_zipper.ply
  stanford/dragon/dragon_100k.ply
)
mkdir -p "$OUT"
view=(--width "$SIZE" --height "$SIZE" --alpha 0.5 --orbit 3 --orbit-view 0 --zoom 1.6 --quiet)
if [ -n "$OLD" ]; then  # the old model, declared for each rule
  python3 - "$OLD" "$OUT" <<'PY'
import json, struct, sys
src, out = sys.argv[1], sys.argv[2]
data = open(src, "rb").read()
at = data.rindex(b'{\n  "activations"')  # the metadata JSON closes the file
length = struct.unpack("<I", data[at - 4:at])[0]
assert at + length == len(data), "unexpected model layout"
meta = json.loads(data[at:])
for rule in ("hybrid", "kbuffer"):
    meta["composite"] = rule
    text = json.dumps(meta, indent=2).encode()
    open("%s/old-%s.mfrnn" % (out, rule), "wb").write(
        data[:at - 4] + struct.pack("<I", len(text)) + text)
PY
fi
for scene in "${scenes[@]}"; do
  name=$(basename "${scene%.*}")
  fragments=$("$MFR" render "$SCENES/$scene" "${view[@]}" -m abuffer --json -o "$OUT/$name-abuffer.png" |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["fragments_generated"])')
  for composite in hybrid kbuffer; do
    perPixel=32; [ "$composite" = kbuffer ] && perPixel=12
    budgets=""
    for share in 25 50; do
      budgets+="${budgets:+,}$((perPixel * SIZE * SIZE + fragments * 8 * share / 100))B"
    done
    dir="$OUT/${name}_${composite}"
    echo "measure-learned: $dir ($fragments fragments, budgets $budgets)"
    "$MFR" compare "$SCENES/$scene" "${view[@]}" --budget "$budgets" \
      --methods fkb,dkb,dkb-fill,dkb-curve,optimal --composite "$composite" --out "$dir"
    if [ -n "$OLD" ]; then
      "$MFR" compare "$SCENES/$scene" "${view[@]}" --budget "$budgets" --methods dkb,optimal \
        --composite "$composite" --model "$OUT/old-$composite.mfrnn" --out "$dir-old"
    fi
  done
done
python3 - "$OUT" <<'PY'
import glob, json, math, os, sys
from collections import defaultdict
ratios = defaultdict(list)
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*", "results.json"))):
    old = os.path.dirname(path).endswith("-old")
    r = json.load(open(path))
    for b in r["budgets"]:
        mse = {m["name"]: m.get("mse_linear") for m in b["methods"]}
        opt = mse.get("optimal")
        for name, v in mse.items():
            if name == "optimal" or not opt or v is None or v <= 0:
                continue
            ratios[(r["compositing"], name + (" (old model)" if old else ""))].append(v / opt)
print("| rule | method | cases | geomean MSE / optimal |")
print("|---|---|---|---|")
for (rule, name), v in sorted(ratios.items()):
    g = math.exp(sum(math.log(x) for x in v) / len(v))
    print("| %s | %s | %d | %.2fx |" % (rule, name, len(v), g))
PY
