#!/usr/bin/env bash
# Reproduces the deep k-buffer's shipped model, models/dkb-default.mfrnn, from the project's
# procedural scenes only (no real scene is seen in training), with `mfr dataset` and `mfr train`:
#
#   scripts/train-model.sh [OPTIONS] [MFR_BINARY] [WORK_DIR]   (defaults: build/mfr,
#                                                               build/dkb-training)
#
# Writes WORK_DIR/procedural.mfrds, then models/dkb-default.mfrnn with its training log
# (models/dkb-default.log.csv) and loss curve (models/dkb-default.loss.png). Deterministic: the
# same binary gives the same bytes (the thread count and the folders do not matter: the model
# records each dataset's file name and FNV-1a 64 hash, not its path). Rebuild afterwards to
# compile the new model into the library. About 1 minute for the dataset and about 9 minutes for
# the training on 2 cores.
#
# Options (defaults: the shipped model's settings; relative paths are relative to the repository
# root, where the script runs):
#   --tiny          the scaled-down preset of the reproducibility test (tests/model_repro_test.sh):
#                   the same scenes at 32x32, 2 orbit views, 3 epochs, output
#                   models/test/dkb-tiny.mfrnn (about a second); the options below override it
#   --size N        width and height of every view (256)
#   --orbit N       orbit views per scene (8)
#   --scenes LIST   space-separated scenes; the last is held out for validation
#                   ("procedural:layers procedural:hairball procedural:smoke procedural:spheres
#                   procedural:bottles")
#   --epochs N      training epochs (150)
#   --out FILE      the model; its log and loss curve go beside it, FILE without .mfrnn plus
#                   .log.csv and .loss.png (models/dkb-default.mfrnn)
#
# The test `ModelReproducesTinyReference` (ctest) runs `--tiny` in a temporary folder and compares
# the model's bytes with models/test/dkb-tiny.mfrnn, so any change of the training, dataset or
# feature code that changes the model fails it. After such an intended change, regenerate both:
#
#   scripts/train-model.sh --tiny build/mfr     # models/test/dkb-tiny.mfrnn (+ log, loss curve)
#   scripts/train-model.sh build/mfr            # models/dkb-default.mfrnn (~10 minutes)
#
# then rebuild (the default model is compiled into the library). When the features or the target
# change, bump kDkbFeatureSet (include/mfr/method/dkb_features.hpp) or kDkbTargetScaling
# (include/mfr/learn/dataset.hpp) first: the built-in model must declare both.
set -euo pipefail
cd "$(dirname "$0")/.."

tiny=0 size="" orbit="" scenes="" epochs="" out=""
positional=()
while (($#)); do
  case "$1" in
    --tiny) tiny=1 ;;
    --size) size=$2; shift ;;
    --orbit) orbit=$2; shift ;;
    --scenes) scenes=$2; shift ;;
    --epochs) epochs=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "train-model.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) positional+=("$1") ;;
  esac
  shift
done
if ((${#positional[@]} > 2)); then
  echo "train-model.sh: at most two arguments, MFR_BINARY and WORK_DIR (see --help)" >&2
  exit 2
fi
MFR=${positional[0]:-build/mfr}
WORK=${positional[1]:-build/dkb-training}

# bottles last: held out for validation (closest to the real glass objects)
: "${scenes:=procedural:layers procedural:hairball procedural:smoke procedural:spheres procedural:bottles}"
if ((tiny)); then
  : "${size:=32}" "${orbit:=2}" "${epochs:=3}" "${out:=models/test/dkb-tiny.mfrnn}"
else
  : "${size:=256}" "${orbit:=8}" "${epochs:=150}" "${out:=models/dkb-default.mfrnn}"
fi
read -r -a sceneList <<<"$scenes"
if ((${#sceneList[@]} < 2)); then
  echo "train-model.sh: --scenes needs at least two scenes (the last is for validation)" >&2
  exit 2
fi
validation=${sceneList[${#sceneList[@]} - 1]}
stem=${out%.mfrnn}
mkdir -p "$WORK" "$(dirname "$out")"

# the scenes x ORBIT views x 5 budgets (one fragment per covered pixel ... all fragments), 20% of
# the covered pixels of each, at SIZE x SIZE
"$MFR" dataset "${sceneList[@]}" --width "$size" --height "$size" --orbit "$orbit" \
  --budget-steps 5 --sample 0.2 --seed 1 --quiet -o "$WORK/procedural.mfrds"

"$MFR" train "$WORK/procedural.mfrds" --validation-scene "$validation" \
  --epochs "$epochs" --learning-rate 1e-3 --batch 512 --momentum 0 --seed 1 --quiet \
  -o "$out" --log "$stem.log.csv" --loss-curve "$stem.loss.png"
if [ "$out" = models/dkb-default.mfrnn ]; then
  echo "$out written; rebuild (make build) to compile it in"
else
  echo "$out written"
fi
