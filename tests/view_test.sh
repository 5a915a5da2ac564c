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

# --help states the viewer's own default engine (gl), as docs/VIEWER.md and the panel do
"$MFR" view --help | tr -s ' \n' '  ' | grep -q -- 'Engine that renders: [a-z|]* (default gl)' ||
  { echo "FAIL: view --help does not say --engine defaults to gl"; "$MFR" view --help; exit 1; }
echo "ok: view --help: --engine (default gl)"

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

# (e) file cameras, WASD fly, method parameters, bytes by category, compare line, open a scene
cat >cams.json <<'JSON'
{"mesh": "procedural:spheres",
 "cameras": [{"eye": [0.3, 0.8, 3.2], "target": [0, 0, 0], "fov": 45},
             {"eye": [2.6, 1.4, -1.2], "target": [0, 0.1, 0], "up": [0, 1, 0], "fov": 55}]}
JSON
opts=(--method fkb --budget 256KB --width $S --height $S)
for v in 0 1; do "$MFR" render cams.json --engine gl "${opts[@]}" --view $v -q -o cam_ref$v.png; done
"$MFR" render procedural:layers --engine gl "${opts[@]}" -q -o open_ref.png
"$MFR" render procedural:layers --engine gl --method fkb+occupancy --occupancy-d 4 --budget 2MB \
  --width $S --height $S -q -o occ_ref.png
"$MFR" render procedural:layers --engine gl --method vkb --budget 2MB --importance-alpha 0.25 \
  --n-limit 8 --no-noise --width $S --height $S -q -o vkb_ref.png
cat >cams_script.json <<'JSON'
[{"file_camera": 1, "screenshot": "cam1.png"},
 {"next_camera": 1, "screenshot": "cam0.png"},
 {"fly": [0.1, 0.05, 0.3], "copy_command": true, "screenshot": "fly.png"},
 {"open": "procedural:layers", "screenshot": "open.png"},
 {"open": "no_such_scene.gltf", "screenshot": "open_bad.png"},
 {"method": "fkb+occupancy", "budget": "2MB", "screenshot": "occ1.png"},
 {"occupancy_d": 4, "screenshot": "occ.png"},
 {"method": "vkb", "importance": {"alpha": 0.25, "n_limit": 8, "noise_term": false},
  "screenshot": "vkb.png"},
 {"method": "dkb", "model": "no_such_model.mfrnn", "screenshot": "dkb_bad.png"},
 {"method": "fkb", "model": "", "budget_share": 0.5, "screenshot": "share.png"}]
JSON
"$MFR" view cams.json "${opts[@]}" --script cams_script.json --stats-json cams_stats.json >cams_cmd.txt
cmp cam1.png cam_ref1.png || { echo "FAIL: file_camera 1 != mfr render --view 1"; exit 1; }
cmp cam0.png cam_ref0.png || { echo "FAIL: next file camera (0) != mfr render --view 0"; exit 1; }
"$MFR" view cams.json "${opts[@]}" --view 1 --frames 2 --screenshot start1.png
cmp start1.png cam_ref1.png || { echo "FAIL: mfr view --view 1 != mfr render --view 1"; exit 1; }
cmd=$(grep '^mfr render ' cams_cmd.txt | head -1)
cmd=${cmd% -o view.png}
eval "\"$MFR\" ${cmd#mfr } -q -o fly_ref.png"
cmp fly.png fly_ref.png || { echo "FAIL: flown screenshot != its copied command: $cmd"; exit 1; }
! cmp -s fly.png cam0.png || { echo "FAIL: fly did not move the camera"; exit 1; }
cmp open.png open_ref.png || { echo "FAIL: opened scene != mfr render of it"; exit 1; }
cmp open_bad.png open_ref.png || { echo "FAIL: a bad open changed the scene"; exit 1; }
cmp occ.png occ_ref.png || { echo "FAIL: occupancy_d 4 != render --occupancy-d 4"; exit 1; }
cmp vkb.png vkb_ref.png || { echo "FAIL: vkb parameters != render's"; exit 1; }
compare=$(grep '^mfr compare ' cams_cmd.txt | head -1)
[[ "$compare" == *"--methods fkb --budget 262144 "*"--camera "* ]] ||
  { echo "FAIL: compare line: $compare"; cat cams_cmd.txt; exit 1; }
eval "\"$MFR\" ${compare#mfr } -q" >/dev/null
[ -s compare/results.json ] || { echo "FAIL: the copied compare line wrote no results.json"; exit 1; }
if "$MFR" render procedural:layers --engine gl --method dkb --budget 256KB \
  --model no_such_model.mfrnn --width $S --height $S -q -o x.png 2>dkb_err.txt; then
  echo "FAIL: render loaded a missing model"; exit 1
fi
python3 - <<'PY'
import json
stats = json.load(open("cams_stats.json"))
shots = {s["path"]: s for s in stats["screenshots"]}
assert shots["cam1.png"]["file_camera"] == 1 and shots["cam0.png"]["file_camera"] == 0, shots
assert shots["open.png"]["scene"] == "procedural:layers" and not shots["open.png"]["notice"]
bad = shots["open_bad.png"]
assert bad["scene"] == "procedural:layers" and "no_such_scene.gltf" in bad["notice"], bad
assert "\n" not in bad["notice"], bad
err = open("dkb_err.txt").read().strip()
dkb = shots["dkb_bad.png"]["error"]
assert dkb and dkb in err, (dkb, err)
for s in stats["screenshots"]:
    if "bytes_used" in s:
        assert sum(s["bytes_by_category"].values()) == s["bytes_used"], s
occ1, occ4 = shots["occ1.png"]["bytes_by_category"], shots["occ.png"]["bytes_by_category"]
assert occ1 != occ4, f"occupancy d changes no category: {occ1}"
share = shots["share.png"]
assert share["truth_bytes"] > 0 and abs(share["budget_bytes"] - share["truth_bytes"] / 2) <= 1, share
assert share["bytes_used"] <= share["budget_bytes"], share
print(f"ok: file cameras, fly, open (a bad one: {bad['notice']}), occupancy d, vkb parameters, "
      f"--model error ({dkb}), budget share, bytes by category {occ4}")
PY
echo "ok: file cameras, fly, open, occupancy d, vkb == mfr render; compare line runs: $compare"

# (f) every map in one action, the vkb fovea, and renders on the worker thread
"$MFR" render procedural:layers --engine gl --method vkb --budget 1MB --width $S --height $S \
  --fovea 20,30 -q -o fov_ref.png --k-map fov_kmap.png --importance-map fov_imp.png \
  --depth-complexity fov_depth.png
"$MFR" render procedural:layers --engine gl --method vkb --budget 1MB --width $S --height $S \
  -q -o centre_ref.png
cat >maps.json <<'JSON'
[{"method": "vkb", "budget": "1MB", "importance": {"fovea": [20, 30]}},
 {"copy_command": true, "screenshot_maps": "fov"},
 {"importance": {"fovea": null}, "screenshot": "centre.png"}]
JSON
for thread in off on; do
  rm -f fov-*.png centre.png
  "$MFR" view procedural:layers --width $S --height $S --script maps.json --render-thread $thread \
    --stats-json maps_$thread.json >maps_cmd.txt
  cmp fov-image.png fov_ref.png || { echo "FAIL: maps ($thread): image != render --fovea"; exit 1; }
  cmp fov-kmap.png fov_kmap.png || { echo "FAIL: maps ($thread): kmap != render --k-map"; exit 1; }
  cmp fov-importance.png fov_imp.png ||
    { echo "FAIL: maps ($thread): importance != render --importance-map"; exit 1; }
  cmp fov-depth.png fov_depth.png ||
    { echo "FAIL: maps ($thread): depth != render --depth-complexity"; exit 1; }
  for m in truth flip; do [ -s fov-$m.png ] || { echo "FAIL: maps: no fov-$m.png"; exit 1; }; done
  cmp centre.png centre_ref.png || { echo "FAIL: fovea null ($thread) != image centre"; exit 1; }
  ! cmp -s fov_ref.png centre_ref.png || { echo "FAIL: the fovea changes nothing"; exit 1; }
  grep -q -- "--fovea 20,30" maps_cmd.txt || { echo "FAIL: copied command lacks --fovea"; exit 1; }
done
"$MFR" view procedural:layers --width $S --height $S --method fkb --budget 256KB --frames 2 \
  --render-thread on --screenshot thread.png
"$MFR" render procedural:layers --engine gl --method fkb --budget 256KB --width $S --height $S \
  -q -o thread_ref.png
cmp thread.png thread_ref.png || { echo "FAIL: --render-thread on --frames != render"; exit 1; }
echo "ok: screenshot_maps == render's image/k-map/importance/depth maps; --fovea; render thread"

# (g) real input events (xdotool through the X server): a left drag orbits, W flies forward,
# ctrl+click places the vkb fovea, Esc quits; an interactive session, so renders run on the worker
if command -v xdotool >/dev/null; then
  "$MFR" view procedural:spheres --width $S --height $S --method vkb --budget 400KB \
    --stats-json input.json >/dev/null 2>input_err.txt &
  pid=$!
  wid=$(timeout 60 xdotool search --sync --onlyvisible --name "mfr view" | head -1)
  [ -n "$wid" ] || { echo "FAIL: input session: no window"; cat input_err.txt; exit 1; }
  settle() { sleep "${1:-4}"; }  # renders of a 128x128 view take < 2 s here, even when loaded
  settle 6
  xdotool mousemove --window "$wid" 64 64 mousedown 1
  for i in 1 2 3 4 5 6; do xdotool mousemove --window "$wid" $((64 + i * 8)) 64; sleep 0.1; done
  xdotool mouseup 1
  settle
  xdotool keydown --window "$wid" w; sleep 0.5; xdotool keyup --window "$wid" w
  settle
  xdotool mousemove --window "$wid" 30 40 keydown ctrl click 1 keyup ctrl
  settle
  xdotool key --window "$wid" Escape
  # Esc quits within a minute, or the session failed (rather than hanging until ctest's timeout)
  for _ in $(seq 60); do kill -0 $pid 2>/dev/null || break; sleep 1; done
  if kill -0 $pid 2>/dev/null; then
    kill $pid; echo "FAIL: input session: Esc did not quit within 60 s"; cat input_err.txt; exit 1
  fi
  rc=0; wait $pid || rc=$?
  [ "$rc" -eq 0 ] || { echo "FAIL: input session exit $rc"; cat input_err.txt; exit 1; }
  python3 - <<'PY'
import json
renders = json.load(open("input.json"))["renders"]
cams = [[float(x) for x in r["camera"].split(",")] for r in renders]
eye, target = lambda c: c[0:3], lambda c: c[3:6]
start = cams[0]
orbited = [c for c in cams if target(c) == target(start) and eye(c) != eye(start)]
assert orbited, f"the drag did not orbit: {cams}"
flown = [c for c in cams if target(c) != target(start)]
assert flown, f"W did not fly: {cams}"
fovea = [r["fovea"] for r in renders if "fovea" in r]
assert fovea and abs(fovea[-1][0] - 30) <= 1 and abs(fovea[-1][1] - 40) <= 1, renders[-1]
print(f"ok: real input: {len(renders)} renders, drag orbited, W flew, ctrl+click fovea {fovea[-1]}")
PY
elif [ "${CI:-}" = "true" ]; then
  echo "FAIL (CI=true): xdotool not installed (Debian: xdotool)"; exit 1
else
  echo "SKIP: real input events: xdotool not installed"
fi

# (c) the window with its panel
"$MFR" view procedural:layers --width $S --height $S --method kplus-array --budget 200KB \
  --mode wiper --frames 3 --screenshot ui.png --screenshot-ui
[ -s ui.png ] || { echo "FAIL: no panel screenshot"; exit 1; }
if [ -n "${MFR_VIEW_KEEP:-}" ]; then cp ui.png "$MFR_VIEW_KEEP"; fi
echo "ok: panel screenshot"
INNER
xvfb-run -a -s "-screen 0 1280x1024x24" bash session.sh "$MFR"
