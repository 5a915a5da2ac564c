#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang 14 (ASan + UBSan) in build-fuzz and runs each one
# for SECONDS, one after the other, in one process each.
#
#   scripts/fuzz.sh SECONDS [TARGET...]      (default: every fuzz/fuzz_TARGET.cpp)
#
# Corpus: build-fuzz/corpus/TARGET (kept between runs), read together with fuzz/seeds/TARGET, the
# stored crash inputs fuzz/crashes/TARGET and inputs copied at run time into build-fuzz/extra-seeds
# (../shared/scenes files of the target's format, the tests' PNGs, the shipped models); nothing is
# copied into the repository. A crash, leak, timeout (over TIMEOUT seconds per input, default 1) or
# out-of-memory (over RSS_MB, default 2048) leaves its input in fuzz/crashes/TARGET/ and makes the
# script exit 1 after the remaining targets ran. Per target the log is build-fuzz/logs/TARGET.log;
# the table of executions, coverage (cov, ft) and findings is printed at the end and written to
# build-fuzz/logs/summary.md. Environment: BUILD (build-fuzz), JOBS (build jobs, 2), TIMEOUT, RSS_MB,
# CXX (clang++-14), FUZZ_FLAGS (more libFuzzer flags).
set -euo pipefail

if [ $# -lt 1 ] || ! [[ "$1" =~ ^[0-9]+$ ]]; then
  echo "usage: scripts/fuzz.sh SECONDS [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
build=${BUILD:-build-fuzz}
jobs=${JOBS:-2}
timeout=${TIMEOUT:-1}
rss=${RSS_MB:-2048}
cxx=${CXX:-clang++-14}

# clang 14 and its runtimes (libFuzzer, ASan, UBSan) from Debian, installed when missing.
packages=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "fuzz: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
bash scripts/install-deps.sh >/dev/null

all_targets=()
for f in fuzz/fuzz_*.cpp; do
  t=$(basename "$f" .cpp)
  all_targets+=("${t#fuzz_}")
done
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [ -f "fuzz/fuzz_$t.cpp" ] || { echo "fuzz: unknown target '$t' (known: ${all_targets[*]})" >&2; exit 2; }
done

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" -DMFR_FUZZ=ON \
  -DMFR_BUILD_TESTS=OFF -DMFR_BUILD_BENCH=OFF -DMFR_BUILD_PYTHON=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target $(printf 'fuzz_%s ' "${targets[@]}")

# Inputs of each format from outside the repository, copied into the build folder.
max_len_of() {
  case $1 in
    units | camera | procedural) echo 256 ;;
    json_scene) echo 4096 ;;
    obj | ply) echo 32768 ;;
    *) echo 65536 ;;
  esac
}
extra_seeds() {  # TARGET -> folder
  local t=$1 dir="$build/extra-seeds/$1" shared="$root/../shared/scenes"
  rm -rf "$dir"
  mkdir -p "$dir"
  local pattern=""
  case $t in
    gltf) pattern='*.gltf' ;;
    glb) pattern='*.glb' ;;
    ply) pattern='*.ply' ;;
    obj) pattern='*.obj' ;;
    png) pattern='*.png' ;;
  esac
  if [ -n "$pattern" ] && [ -d "$shared" ]; then
    find "$shared" -type f -name "$pattern" -exec cp {} "$dir/" \;
  fi
  case $t in
    png) cp tests/data/flip/*.png "$dir/" 2>/dev/null || true ;;
    mfrnn) find models -name '*.mfrnn' -exec cp {} "$dir/" \; ;;
  esac
  echo "$dir"
}

mkdir -p "$build/logs"
summary="$build/logs/summary.md"
{
  echo "| target | seconds | executions | exec/s | cov | ft | corpus | findings |"
  echo "|---|---:|---:|---:|---:|---:|---:|---|"
} >"$summary"
failed=0
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0"
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  crashes="fuzz/crashes/$t"
  mkdir -p "$corpus" "$crashes"
  extra=$(extra_seeds "$t")
  dict=()
  [ -f "fuzz/dicts/$t.dict" ] && dict=(-dict="fuzz/dicts/$t.dict")
  before=$(find "$crashes" -type f | wc -l)
  log="$build/logs/$t.log"
  echo "fuzz: $t for ${seconds}s (log $log)"
  status=0
  # shellcheck disable=SC2086
  "$build/fuzz_$t" "$corpus" "fuzz/seeds/$t" "$crashes" "$extra" "${dict[@]}" \
    -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb="$rss" \
    -max_len="$(max_len_of "$t")" -artifact_prefix="$crashes/" -print_final_stats=1 \
    ${FUZZ_FLAGS:-} >"$log" 2>&1 || status=$?
  after=$(find "$crashes" -type f | wc -l)
  execs=$(grep -a 'stat::number_of_executed_units' "$log" | tail -1 | awk '{print $2}' || true)
  rate=$(grep -a 'stat::average_exec_per_sec' "$log" | tail -1 | awk '{print $2}' || true)
  last=$(grep -a -E '^#[0-9]+' "$log" | grep -a 'cov:' | tail -1 || true)
  [ -n "$execs" ] || execs=$(sed -n 's/^#\([0-9]*\).*/\1/p' <<<"$last")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  units=$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<<"$last")
  findings="none"
  if [ "$status" -ne 0 ] || [ "$after" -gt "$before" ]; then
    failed=1
    findings="exit $status, $((after - before)) new input(s) in $crashes: $(grep -a -m1 -E 'ERROR: |runtime error|fuzz property failed' "$log" | cut -c1-120 || true)"
    echo "fuzz: $t FAILED: $findings" >&2
    tail -40 "$log" >&2
  fi
  echo "| $t | $seconds | ${execs:-?} | ${rate:-?} | ${cov:-?} | ${ft:-?} | ${units:-?} | $findings |" >>"$summary"
done
cat "$summary"
exit $failed
