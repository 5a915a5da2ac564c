#!/usr/bin/env bash
# mfr view under Xvfb (issue 16): scripted sessions whose screenshots equal `mfr render --engine gl`
# byte for byte (two scenes, the start camera and an orbited one via "copy command"), a sweep of
# every method and view mode (non-empty, different where they should differ, bytes_used within
# the budget), a screenshot with the panel, and the one-line error without a display.
# Skips (77) without xvfb-run or a GL engine, unless CI=true: then that is a failure.
set -euo pipefail
MFR=$(realpath "$1")
skip() {
  if [ "${CI:-}" = "true" ]; then echo "FAIL (CI=true): $1"; exit 1; fi
  echo "SKIP: $1"; exit 77
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# (d) no display: one line naming the problem and pointing to mfr render, exit 1
set +e
env -u DISPLAY -u WAYLAND_DISPLAY "$MFR" view procedural:layers --frames 1 2>err.txt >/dev/null
rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "FAIL: no display: exit $rc"; cat err.txt; exit 1; }
[ "$(wc -l <err.txt)" -eq 1 ] || { echo "FAIL: no display: not one line"; cat err.txt; exit 1; }
grep -q "no display" err.txt && grep -q "mfr render" err.txt ||
  { echo "FAIL: no display: message"; cat err.txt; exit 1; }
echo "ok: no display -> $(cat err.txt)"
# bad options: render's one-line errors, before any window
set +e
"$MFR" view procedural:nosuchscene --frames 1 2>err.txt >/dev/null; rc1=$?
"$MFR" render procedural:nosuchscene -q -o x.png 2>err_render.txt >/dev/null
set -e
[ "$rc1" -eq 1 ] && [ "$(wc -l <err.txt)" -eq 1 ] && cmp -s err.txt err_render.txt ||
  { echo "FAIL: bad scene: view and render errors differ"; cat err.txt err_render.txt; exit 1; }
echo "ok: bad scene -> $(cat err.txt)"

command -v xvfb-run >/dev/null || skip "xvfb-run not installed (Debian: xvfb xauth)"
"$MFR" render procedural:layers --engine gl --width 8 --height 8 -q -o probe.png 2>probe.txt ||
  skip "no GL engine here: $(cat probe.txt)"

cat >session.sh <<'INNER'
set -euo pipefail
MFR=$1
S=128
# (a) screenshot == mfr render --engine gl, two scenes, start camera and an orbited one
for scene in procedural:layers procedural:spheres; do
  opts=(--method fkb --budget 256KB --width $S --height $S)
  "$MFR" render "$scene" --engine gl "${opts[@]}" -q -o ref.png
  cat >orbit.json <<'JSON'
[{"screenshot": "start.png"}, {"orbit": 35, "pitch": 12}, {"zoom": 1.3},
 {"copy_command": true, "screenshot": "orbit.png"}]
JSON
  "$MFR" view "$scene" "${opts[@]}" --script orbit.json >cmd.txt
  cmp start.png ref.png || { echo "FAIL: $scene: view screenshot != mfr render --engine gl"; exit 1; }
  cmd=$(grep '^mfr render ' cmd.txt | tail -1)
  [ -n "$cmd" ] || { echo "FAIL: no copied command"; cat cmd.txt; exit 1; }
  cmd=${cmd% -o view.png}
  eval "\"$MFR\" ${cmd#mfr } -q -o orbit_ref.png"
  cmp orbit.png orbit_ref.png ||
    { echo "FAIL: $scene: orbited screenshot != its copied command: $cmd"; exit 1; }
  "$MFR" view "$scene" "${opts[@]}" --frames 3 --screenshot frames.png --stats-json frames.json
  python3 -c "import json,sys; r=json.load(open('frames.json'))['renders']; sys.exit(len(r) != 1)" ||
    { echo "FAIL: $scene: re-rendered frames where nothing changed"; cat frames.json; exit 1; }
  cmp frames.png ref.png || { echo "FAIL: $scene: --frames/--screenshot != render"; exit 1; }
  echo "ok: $scene: screenshots == mfr render --engine gl (start camera and: $cmd)"
done

# --engine cpu in the viewer: the same bytes as mfr render --engine cpu
"$MFR" render procedural:spheres --engine cpu --method kplus-heap --budget 256KB --width $S \
  --height $S -q -o cpu_ref.png
"$MFR" view procedural:spheres --engine cpu --method kplus-heap --budget 256KB --width $S \
  --height $S --frames 2 --screenshot cpu.png
cmp cpu.png cpu_ref.png || { echo "FAIL: --engine cpu: view screenshot != mfr render"; exit 1; }
echo "ok: --engine cpu: screenshot == mfr render --engine cpu"

# (b) every method and every view mode
"$MFR" view --list-methods >methods.txt
python3 - "$S" <<'PY'
import json
methods = open("methods.txt").read().split()
steps = []
for m in methods:
    mb = 0 if m == "abuffer" else 1  # the A-buffer refuses a budget below its exact size
    steps += [{"method": m, "budget_mb": mb, "mode": "image"}, {"screenshot": f"m_{m}.png"}]
for mb in [0.25, 0.5, 1, 2, 4]:  # the budget slider
    steps += [{"method": "kplus-array", "budget_mb": mb}, {"screenshot": f"b_{mb}.png"}]
steps += [{"method": "fkb", "budget_mb": 1}]
for mode in ["image", "depth", "kmap", "importance", "truth", "flip", "wiper"]:
    steps += [{"mode": mode}, {"screenshot": f"v_{mode}.png"}]
json.dump(steps, open("sweep.json", "w"))
PY
"$MFR" view procedural:layers --width $S --height $S --script sweep.json --stats-json sweep_stats.json
python3 - <<'PY'
import hashlib, json
stats = json.load(open("sweep_stats.json"))
shots = {s["path"]: s for s in stats["screenshots"]}
digest = lambda p: hashlib.sha256(open(p, "rb").read()).hexdigest()
refused, ran = [], []
for path, s in shots.items():
    if s["error"]:
        refused.append(f'{s["method"]}/{s["mode"]}')
        continue
    assert s["pixels_unlike_corner"] > 0, f"empty screenshot {path}"
    ran.append(path)
for r in stats["renders"]:
    if "bytes_used" in r and r["budget_bytes"] > 0 and r["method"] not in ("abuffer",):
        assert r["bytes_used"] <= r["budget_bytes"], f"over budget: {r}"
for m in ["abuffer", "zbuffer", "fkb", "kplus-array", "kplus-heap"]:
    assert not shots[f"m_{m}.png"]["error"], shots[f"m_{m}.png"]
for m in ["zbuffer", "fkb", "kplus-array", "kplus-heap"]:  # bounded at 1 MB: not the A-buffer
    assert digest(f"m_{m}.png") != digest("m_abuffer.png"), f"{m} == abuffer"
modes = ["image", "depth", "kmap", "truth", "flip", "wiper"]
for m in modes:
    assert not shots[f"v_{m}.png"]["error"], shots[f"v_{m}.png"]
d = {m: digest(f"v_{m}.png") for m in modes}
assert len(set(d.values())) == len(modes), f"view modes not all different: {d}"
budgets = [digest(f"b_{mb}.png") for mb in [0.25, 0.5, 1, 2, 4]]
assert len(set(budgets)) > 1, "the budget changes nothing"
print(f"ok: {len(ran)} screenshots non-empty, modes differ, bytes_used <= budget in "
      f"{len(stats['renders'])} renders; refused by this engine: {', '.join(refused) or 'none'}")
PY

# (c) the window with its panel
"$MFR" view procedural:layers --width $S --height $S --method kplus-array --budget 200KB \
  --mode wiper --frames 3 --screenshot ui.png --screenshot-ui
[ -s ui.png ] || { echo "FAIL: no panel screenshot"; exit 1; }
if [ -n "${MFR_VIEW_KEEP:-}" ]; then cp ui.png "$MFR_VIEW_KEEP"; fi
echo "ok: panel screenshot"
INNER
xvfb-run -a -s "-screen 0 1280x1024x24" bash session.sh "$MFR"
