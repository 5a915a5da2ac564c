#!/usr/bin/env bash
# examples/train_dkb.py end to end on a tiny dataset: `mfr dataset` (two procedural scenes, 32x32,
# two views), two epochs of numpy training, the model saved through the mfr module; then checks
# that the loss went down, that the model declares the deep k-buffer's features and target, and
# that `mfr render -m dkb --model` with the numpy-trained file gives the image the example
# rendered through the module.
#
#   python_train_example_test.sh PYTHON BUILD/python BUILD/mfr SOURCE_DIR
set -euo pipefail
python=$1 pythonpath=$2 mfr=$3 source=$4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$mfr" dataset 'procedural:layers?k=4&r=2' 'procedural:smoke?count=60' --width 32 --height 32 \
  --orbit 2 --budget-steps 3 --quiet -o "$tmp/tiny.mfrds"
PYTHONPATH=$pythonpath PYTHONDONTWRITEBYTECODE=1 "$python" "$source/examples/train_dkb.py" \
  "$tmp/tiny.mfrds" -o "$tmp/numpy.mfrnn" --epochs 2 --batch 64 --seed 3 \
  --render procedural:bottles --budget 96KB --width 48 --height 40 --image "$tmp/py.png" \
  --summary "$tmp/summary.json"
"$mfr" render procedural:bottles -m dkb -M 96KB --model "$tmp/numpy.mfrnn" --width 48 \
  --height 40 --quiet -o "$tmp/cli.png"
cmp "$tmp/py.png" "$tmp/cli.png" || fail "the CLI renders the numpy-trained model differently"

PYTHONPATH=$pythonpath "$python" - "$tmp" <<'PY' || fail "summary or model"
import json, sys
import numpy as np
import mfr
tmp = sys.argv[1]
s = json.load(open(f"{tmp}/summary.json"))
assert len(s["epochs"]) == 2, s
assert s["train_samples"] > 0 and s["validation_samples"] > 0, s  # smoke held out
assert s["final_train_mse"] < s["initial_train_mse"], s
assert s["library_vs_numpy_max_difference"] < 1e-4, s
r = s["render"]
assert r["method"] == "dkb" and 0 < r["bytes_used"] <= r["budget_bytes"] == 96 * 1024, r
model = mfr.load_model(f"{tmp}/numpy.mfrnn")
model.check_dkb()
meta = json.loads(model.metadata)
assert meta["features"] == mfr.FEATURE_SET and meta["target"] == mfr.TARGET_SCALING
t = meta["training"]
assert t["validation_scenes"] == ["procedural:smoke?count=60"], t
assert t["datasets"][0]["fnv1a64"] == mfr.load_dataset(f"{tmp}/tiny.mfrds").file_hash
# not the built-in model: the numpy-trained weights differ from it
assert not np.array_equal(model.weights[0], mfr.builtin_model().weights[0])
print(f"train_dkb: train MSE {s['initial_train_mse']:.4f} -> {s['final_train_mse']:.4f}, "
      f"validation {s['final_validation_mse']:.4f}; dkb renders it as the CLI does")
PY
