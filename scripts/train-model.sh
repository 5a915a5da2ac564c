#!/usr/bin/env bash
# Reproduces the deep k-buffer's shipped model, models/dkb-default.mfrnn, from the project's
# procedural scenes only (no real scene is seen in training), with `mfr dataset` and `mfr train`:
#
#   scripts/train-model.sh [MFR_BINARY] [WORK_DIR]      (defaults: build/mfr, build/dkb-training)
#
# Writes WORK_DIR/procedural.mfrds, then models/dkb-default.mfrnn with its training log
# (models/dkb-default.log.csv) and loss curve (models/dkb-default.loss.png). Deterministic: the
# same binary gives the same bytes (the thread count does not matter). Rebuild afterwards to
# compile the new model into the library. About 1 minute for the dataset and about 9 minutes for the
# training on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
MFR=${1:-build/mfr}
WORK=${2:-build/dkb-training}
mkdir -p "$WORK" models

# 5 procedural scenes x 8 orbit views x 5 budgets (one fragment per covered pixel ... all
# fragments), 20% of the covered pixels of each, at 256x256
"$MFR" dataset procedural:layers procedural:hairball procedural:smoke procedural:spheres \
  procedural:bottles --width 256 --height 256 --orbit 8 --budget-steps 5 --sample 0.2 --seed 1 \
  --quiet -o "$WORK/procedural.mfrds"

# held-out scene for validation: bottles (closest to the real glass objects)
"$MFR" train "$WORK/procedural.mfrds" --validation-scene procedural:bottles \
  --epochs 150 --learning-rate 1e-3 --batch 512 --momentum 0 --seed 1 --quiet \
  -o models/dkb-default.mfrnn --log models/dkb-default.log.csv \
  --loss-curve models/dkb-default.loss.png
echo "models/dkb-default.mfrnn written; rebuild (make build) to compile it in"
