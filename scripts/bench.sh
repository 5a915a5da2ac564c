#!/usr/bin/env bash
# Runs the benchmark programs and plots their results. Builds nothing.
#
#   scripts/bench.sh [BUILD_DIR] [ARGS...]
#
# BUILD_DIR (default: build) holds the bench_* executables; ARGS (e.g. --quick, --reps 5,
# --threads 1) are passed to every program. Each program writes its CSV into bench-results/ (its
# printed tables go to bench-results/NAME.txt as well), then gnuplot (Debian package gnuplot-nox)
# turns every CSV into a PNG with the scripts in scripts/plots/.
set -uo pipefail

build=build
if [[ $# -gt 0 && $1 != -* ]]; then
  build=$1
  shift
fi
out=bench-results
plots="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/plots"
benches=(abuffer k_sweep occupancy capture_modes isa presets dkb frame_costs engines)

mkdir -p "$out"
status=0
start=$SECONDS
for name in "${benches[@]}"; do
  exe="$build/bench_$name"
  if [[ ! -x $exe ]]; then
    echo "bench.sh: $exe not found (build it first: cmake --build $build)" >&2
    status=1
    continue
  fi
  echo "== bench_$name $*"
  t0=$SECONDS
  if ! "$exe" --out "$out" "$@" | tee "$out/$name.txt"; then
    echo "bench.sh: bench_$name failed" >&2
    status=1
  fi
  echo "== bench_$name: $((SECONDS - t0)) s"
  echo
done

if command -v gnuplot >/dev/null 2>&1; then
  for name in "${benches[@]}"; do
    [[ -f $out/$name.csv && -f $plots/$name.gnuplot ]] || continue
    if gnuplot -c "$plots/$name.gnuplot" "$out/$name.csv" "$out/$name.png"; then
      echo "plot: $out/$name.png"
    else
      echo "bench.sh: plotting $out/$name.csv failed" >&2
      status=1
    fi
  done
else
  echo "bench.sh: gnuplot not found (Debian package gnuplot-nox): CSV files only, no plots" >&2
fi
echo "bench.sh: done in $((SECONDS - start)) s, results in $out/"
exit $status
