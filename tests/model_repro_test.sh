#!/usr/bin/env bash
# Retrains the deep k-buffer's model from the same code with the same script as the shipped one,
# scaled down (scripts/train-model.sh --tiny: the same procedural corpus at 32x32 and 24x24, one
# orbit view each, 3 epochs, hybrid targets), in a temporary folder, and compares the model's bytes with the committed reference
# models/test/dkb-tiny.mfrnn. The model holds the weights and the metadata, which records the
# feature set, the target definition and each dataset's FNV-1a 64 hash: a change of the training,
# dataset or feature code that changes any of them fails here. After an intended change,
# regenerate the reference (and the shipped model) as scripts/train-model.sh describes.
# Usage: model_repro_test.sh path/to/mfr [path/to/repository]
set -euo pipefail

mfr=${1:?usage: model_repro_test.sh path/to/mfr [path/to/repository]}
root=${2:-$(cd "$(dirname "$0")/.." && pwd)}
mfr=$(cd "$(dirname "$mfr")" && pwd)/$(basename "$mfr")
reference="$root/models/test/dkb-tiny.mfrnn"
[ -f "$reference" ] || { echo "model_repro_test: FAIL: $reference is missing" >&2; exit 1; }

work=$(mktemp -d "${TMPDIR:-/tmp}/mfr_model_repro.XXXXXX")
trap 'rm -rf "$work"' EXIT
start=$(date +%s)
bash "$root/scripts/train-model.sh" --tiny --out "$work/dkb-tiny.mfrnn" "$mfr" "$work/data"
echo "model_repro_test: retrained in $(($(date +%s) - start)) s"

# the model's JSON metadata: the bytes from '{' before its first key ("activations") to the end
metadata() {
  local at
  at=$(LC_ALL=C grep -abo '"activations"' "$1" | tail -n 1 | cut -d: -f1) || return 0
  tail -c +"$((at - 3))" "$1"
  echo
}

if ! cmp "$work/dkb-tiny.mfrnn" "$reference"; then
  echo "model_repro_test: FAIL: the retrained tiny model differs from $reference" >&2
  echo "  metadata (< retrained, > reference):" >&2
  diff <(metadata "$work/dkb-tiny.mfrnn") <(metadata "$reference") >&2 || true
  echo "  If the change is intended, regenerate the reference with scripts/train-model.sh --tiny" >&2
  echo "  and models/dkb-default.mfrnn with scripts/train-model.sh (see the script)." >&2
  exit 1
fi
echo "model_repro_test: OK, bytes equal $reference"
