#!/usr/bin/env bash
# Reproduces DFAOIT's shipped network (include/mfr/method/dfaoit.hpp) from the project's procedural
# scenes only (../shared/scenes/ is never seen), with `mfr dataset --target dfaoit` and `mfr train`:
#
#   scripts/train-dfaoit.sh [--tiny] [--epochs N] [--out FILE] [MFR_BINARY] [WORK_DIR]
#                           (defaults: build/mfr, build/dfaoit-training)
#
#   models/dfaoit.mfrnn   with its training log (.log.csv) and loss curve (.loss.png) beside it
#
# Deterministic: the same binary gives the same bytes (the model records each dataset's file name
# and FNV-1a 64 hash, not its path). Rebuild afterwards to compile the model into the library.
#
# The corpus is scripts/train-model.sh's (every procedural family, two parameter sets each, the
# bottles family held out for validation), in two passes with different sizes, cameras and alphas:
#   pass A: 128x128, 4 orbit views, zoom 1, the families' own per-material alphas
#   pass B: 192x192, 3 orbit views, zoom 1.6, every material at alpha 0.5 (global alpha)
# 30% of each view's pixels of three or more fragments; target: the visibility-weighted mean colour
# behind each pixel's nearest fragment, from the A-buffer's sorted composite. Training: 12-32-32-3,
# mean squared error, SGD with momentum 0.9, learning rate 0.03, batch 256, no regularisation,
# seed 1, 600 epochs.
# Time, measured on 2026-12-05 on the 2-core development machine (`time scripts/train-dfaoit.sh
# build/mfr /tmp/dfaoit-train600`): 1 min 48 s in all; the datasets take a few seconds, the
# training is single-threaded (600 epochs of about 0.17 s over 245,122 samples; 21,133 held out
# for validation). A second run (another folder) gave the same bytes.
#
# Options:
#   --tiny        the scaled-down preset of the reproducibility test (tests/dfaoit_repro_test.sh):
#                 the same scenes at 24x24 and 16x16, one orbit view each, 2 epochs, output
#                 models/test/dfaoit-tiny.mfrnn (seconds)
#   --epochs N    training epochs (600)
#   --out FILE    the model (models/dfaoit.mfrnn); its log and loss curve go beside it
set -euo pipefail
cd "$(dirname "$0")/.."

tiny=0 epochs="" out=""
positional=()
while (($#)); do
  case "$1" in
    --tiny) tiny=1 ;;
    --epochs) epochs=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "train-dfaoit.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) positional+=("$1") ;;
  esac
  shift
done
if ((${#positional[@]} > 2)); then
  echo "train-dfaoit.sh: at most two arguments, MFR_BINARY and WORK_DIR (see --help)" >&2
  exit 2
fi
MFR=${positional[0]:-build/mfr}
WORK=${positional[1]:-build/dfaoit-training}

scenes=(
  "procedural:glassware?seed=11" "procedural:glassware?count=9&shells=3&segments=32&seed=12"
  "procedural:foliage?seed=13" "procedural:foliage?plants=9&leaves=150&seed=14"
  "procedural:particles?seed=15" "procedural:particles?clouds=12&count=600&size=0.08&seed=16"
  "procedural:hair?seed=17" "procedural:hair?strands=600&alpha=0.7&seed=18"
  "procedural:panels?seed=19" "procedural:panels?boxes=48&panels=5&seed=20"
  "procedural:city?seed=21" "procedural:city?rows=10&columns=4&alpha=0.2&seed=22"
  "procedural:layers" "procedural:hairball?strands=1500" "procedural:smoke?count=8000"
  "procedural:spheres"
  "procedural:bottles" "procedural:bottles?count=12&seed=23"  # validation family
)
if ((tiny)); then
  : "${epochs:=2}" "${out:=models/test/dfaoit-tiny.mfrnn}"
  sizeA=24 sizeB=16 orbitA=1 orbitB=1
else
  : "${epochs:=600}" "${out:=models/dfaoit.mfrnn}"
  sizeA=128 sizeB=192 orbitA=4 orbitB=3
fi
mkdir -p "$WORK" "$(dirname "$out")"
common=(--target dfaoit --sample 0.3 --seed 1 --quiet)
nice "$MFR" dataset "${scenes[@]}" --width "$sizeA" --height "$sizeA" --orbit "$orbitA" \
  "${common[@]}" -o "$WORK/dfaoit-a.mfrds"
nice "$MFR" dataset "${scenes[@]}" --width "$sizeB" --height "$sizeB" --orbit "$orbitB" \
  --zoom 1.6 --alpha 0.5 "${common[@]}" -o "$WORK/dfaoit-b.mfrds"
stem=${out%.mfrnn}
nice "$MFR" train "$WORK/dfaoit-a.mfrds" "$WORK/dfaoit-b.mfrds" --validation-family bottles \
  --epochs "$epochs" --learning-rate 0.03 --batch 256 --momentum 0.9 --l1 0 --l2 0 --seed 1 \
  --quiet -o "$out" --log "$stem.log.csv" --loss-curve "$stem.loss.png"
echo "$out written"
exit 0
