#!/usr/bin/env bash
# scripts/gpu-check.sh --quick at 64x64 on the binaries as built (no build, llvmpipe where there is
# no GPU), so that the real-GPU check cannot rot: it runs, prints the GL context, writes the CSV with
# its header, one row per scene and preset, and every row agrees (ok, or refused by both engines
# alike). Without a GL 4.5 context: skipped (exit 77), failed under CI=true.
#
#   tests/gpu_check_test.sh SOURCE_DIR BUILD_DIR
set -uo pipefail

src=$1 build=$2
out=$(mktemp -d) || exit 1
trap 'rm -rf "$out"' EXIT

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

bash "$src/scripts/gpu-check.sh" --no-build --build-dir "$build" --out "$out" --quick --size 64 \
  --time-limit 0 >"$out/log" 2>&1
rc=$?
cat "$out/log"
if [[ $rc == 3 ]]; then
  [[ ${CI:-} == true ]] && fail "no GL 4.5 context under CI=true"
  echo "skipped: no GL 4.5 context"
  exit 77
fi

grep -q '^  renderer  ' "$out/log" || fail "the GL renderer is not printed"
grep -q '^  GL_NV_shader_atomic_int64  ' "$out/log" || fail "the extensions are not printed"
grep -q '^  pass timer  ' "$out/log" || fail "the pass timer is not printed"

csv=$out/gpu-check.csv
[[ -f $csv ]] || fail "no $csv"
header="preset,scene,status,width,height,budget_bytes,pass_timer,gl_frame_ms,gl_passes_ms,\
gl_pass_ms,cpu_frame_ms,gl_over_cpu,fragments,np_equal_fraction,bytes_used_gl,bytes_used_cpu,\
flip_mean,max_abs_diff,renderer,sync,error"
[[ $(head -n 1 "$csv") == "$header" ]] || fail "header: $(head -n 1 "$csv")"

# no comma before the renderer (its field and the error's are quoted where they hold one)
rows=$(tail -n +2 "$csv")
layers=$(grep -c '^[^,]*,layers,' <<<"$rows")
bottles=$(grep -c '^[^,]*,bottles,' <<<"$rows")
((layers >= 20 && layers == bottles)) || fail "rows: layers $layers, bottles $bottles"
bad=$(awk -F, '$3 != "ok" && $3 != "refused"' <<<"$rows")
[[ -z $bad ]] || fail "rows that do not agree:
$bad"
ok=$(awk -F, '$3 == "ok"' <<<"$rows" | wc -l)
((ok >= 20)) || fail "only $ok rows ok"
# an ok row carries its frame times, the timer and the pass list
awk -F, '$3 == "ok" && ($7 != "gpu" && $7 != "wall" || $8 == "" || $10 == "" || $11 == "")' <<<"$rows" |
  grep -q . && fail "an ok row without its timer or frame times"
((rc == 0)) || fail "gpu-check.sh exited $rc"
echo "gpu-check.sh --quick: $ok rows ok, $(($(wc -l <<<"$rows") - ok)) refused alike"
