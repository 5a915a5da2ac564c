#!/usr/bin/env bash
# Retrains DFAOIT's network from the same code with the same script as the shipped one, scaled
# down (scripts/train-dfaoit.sh --tiny: the same procedural corpus at 24x24 and 16x16, one orbit
# view each, 2 epochs), in a temporary folder, and compares the model's bytes with the committed
# reference models/test/dfaoit-tiny.mfrnn. The model holds the weights and the metadata (the
# feature set, the target definition, each dataset's FNV-1a 64 hash): a change of the training,
# dataset or feature code that changes any of them fails here. After an intended change,
# regenerate the reference (and the shipped model) as scripts/train-dfaoit.sh describes.
# Usage: dfaoit_repro_test.sh path/to/mfr [path/to/repository]
set -euo pipefail

mfr=${1:?usage: dfaoit_repro_test.sh path/to/mfr [path/to/repository]}
root=${2:-$(cd "$(dirname "$0")/.." && pwd)}
mfr=$(cd "$(dirname "$mfr")" && pwd)/$(basename "$mfr")
reference="$root/models/test/dfaoit-tiny.mfrnn"
[ -f "$reference" ] || { echo "dfaoit_repro_test: FAIL: $reference is missing" >&2; exit 1; }

work=$(mktemp -d "${TMPDIR:-/tmp}/mfr_dfaoit_repro.XXXXXX")
trap 'rm -rf "$work"' EXIT
start=$(date +%s)
bash "$root/scripts/train-dfaoit.sh" --tiny --out "$work/dfaoit-tiny.mfrnn" "$mfr" "$work/data"
echo "dfaoit_repro_test: retrained in $(($(date +%s) - start)) s"

if ! cmp "$work/dfaoit-tiny.mfrnn" "$reference"; then
  echo "dfaoit_repro_test: FAIL: the retrained tiny model differs from $reference" >&2
  echo "  If the change is intended, regenerate it with scripts/train-dfaoit.sh --tiny" >&2
  echo "  and models/dfaoit.mfrnn with scripts/train-dfaoit.sh (see the script)." >&2
  exit 1
fi
echo "dfaoit_repro_test: OK, bytes equal $reference"
