#!/usr/bin/env bash
# The installed package: `cmake --install` of this build into a temporary prefix (then moved, so
# nothing may point back at the build or source tree), checks the installed files, builds
# examples/consumer against it with find_package(mfr) and with pkg-config, runs both and compares
# their images with the installed CLI's, and imports the installed Python module.
#
#   package_install_test.sh BUILD_DIR SOURCE_DIR CMAKE CXX PYTHON|none
set -euo pipefail
build=$1 source=$2 cmake=$3 cxx=$4 python=$5
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$cmake" --install "$build" --prefix "$tmp/staging" > "$tmp/install.log"
mv "$tmp/staging" "$tmp/prefix"   # relocated: the package must find itself
prefix=$tmp/prefix
libdir=$(cd "$prefix" && dirname "$(find . -name libmfr.a | head -1)")
[ -n "$libdir" ] || fail "libmfr.a not installed"
libdir=${libdir#./}

# --- installed files ---------------------------------------------------------------------------
for f in bin/mfr include/mfr/mfr.hpp include/mfr/cpu/render.hpp include/mfr/engine/engine.hpp include/mfr/scene/load.hpp \
         include/mfr/cpu/raster_frame_impl.hpp "$libdir/libmfr.a" \
         "$libdir/cmake/mfr/mfrConfig.cmake" "$libdir/cmake/mfr/mfrConfigVersion.cmake" \
         "$libdir/cmake/mfr/mfrTargets.cmake" "$libdir/pkgconfig/mfr.pc" \
         share/mfr/models/dkb-default.mfrnn; do
  [ -f "$prefix/$f" ] || fail "$f not installed"
done
# exactly the public headers: every include/mfr header, nothing of src/ (pipeline.hpp, ...)
(cd "$source/include" && find mfr \( -name '*.hpp' -o -name '*.h' \) | sort) > "$tmp/public"
(cd "$prefix/include" && find . -type f | sed 's|^\./||' | sort) > "$tmp/installed"
diff "$tmp/public" "$tmp/installed" || fail "installed headers differ from include/mfr"
for private in $(cd "$source/src" && find . -name '*.hpp' | sed 's|^\./||'); do
  [ ! -e "$prefix/include/$private" ] && [ ! -e "$prefix/include/mfr/$private" ] \
    || fail "private header $private installed"
done
# no installed file refers to the build or source tree
if grep -rlF -e "$build" -e "$source" "$prefix/include" "$prefix/$libdir/cmake" \
     "$prefix/$libdir/pkgconfig"; then
  fail "installed files refer to the build or source tree"
fi
# the model is compiled into the library (the consumers below render dkb from another folder)
grep -q "MFRMLP" "$prefix/$libdir/libmfr.a" || fail "the built-in model is not in libmfr.a"

# --- every public header compiles on its own against the installed tree only (an *_impl.hpp is
# part of the header that includes it), and all of them together --------------------------------
pcflags=$(PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig" pkg-config --cflags mfr)
[ "$(PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig" pkg-config --modversion mfr)" = \
  "$(sed -nE 's/^project\(mfr VERSION ([0-9.]+).*/\1/p' "$source/CMakeLists.txt")" ] \
  || fail "pkg-config --modversion mfr"
: > "$tmp/all_headers.cpp"
while read -r h; do echo "#include <$h>" >> "$tmp/all_headers.cpp"; done < "$tmp/public"
export cxx pcflags tmp
grep -v '_impl\.hpp$' "$tmp/public" | xargs -P 2 -I{} bash -c '
  one=$tmp/one_$(echo {} | tr / _).cpp
  printf "#include <%s>\n#include <%s>\n" {} {} > "$one"   # self-contained and guarded
  "$cxx" -std=c++20 -fsyntax-only $pcflags "$one" || { echo "FAIL: {} does not compile alone"; exit 255; }'
"$cxx" -std=c++20 -fsyntax-only $pcflags "$tmp/all_headers.cpp" || fail "the headers together"
echo "headers: $(wc -l < "$tmp/public") public headers compile alone and together"

# --- examples/consumer with find_package(mfr) --------------------------------------------------
"$cmake" -S "$source/examples/consumer" -B "$tmp/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" > "$tmp/consumer-configure.log" \
  || { cat "$tmp/consumer-configure.log"; fail "configuring the consumer"; }
grep -q "mfr_DIR:PATH=$prefix/$libdir/cmake/mfr" "$tmp/consumer/CMakeCache.txt" \
  || fail "find_package(mfr) did not find the installed package"
"$cmake" --build "$tmp/consumer" -j 2 > "$tmp/consumer-build.log" \
  || { cat "$tmp/consumer-build.log"; fail "building the consumer"; }
mkdir "$tmp/out"
"$tmp/consumer/mfr_consumer" procedural:bottles 4MB "$tmp/out" > "$tmp/stats.txt"
cat "$tmp/stats.txt"

# --- the same consumer through pkg-config -------------------------------------------------------
mkdir "$tmp/out-pc"
PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig" bash -c \
  "'$cxx' -std=c++20 -O1 '$source/examples/consumer/main.cpp' -o '$tmp/consumer-pc' \
   \$(pkg-config --cflags --libs mfr)" || fail "building the consumer with pkg-config"
"$tmp/consumer-pc" procedural:bottles 4MB "$tmp/out-pc" > "$tmp/stats-pc.txt"

# --- outputs: two runs within the budget, PNGs equal to the installed CLI's ----------------------
[ "$(wc -l < "$tmp/stats.txt")" -eq 2 ] || fail "expected two lines of statistics"
mfr=$prefix/bin/mfr
for preset in kplus-dynamic dkb; do
  line=$(grep "\"method\":\"$preset\"" "$tmp/stats.txt") || fail "no statistics for $preset"
  used=$(sed -E 's/.*"bytes_used":([0-9]+).*/\1/' <<< "$line")
  budget=$(sed -E 's/.*"budget_bytes":([0-9]+).*/\1/' <<< "$line")
  captured=$(sed -E 's/.*"fragments_captured":([0-9]+).*/\1/' <<< "$line")
  [ "$budget" -eq 4194304 ] && [ "$used" -gt 0 ] && [ "$used" -le "$budget" ] \
    && [ "$captured" -gt 0 ] || fail "$preset: bytes_used $used, budget $budget, captured $captured"
  [ "$(head -c 8 "$tmp/out/$preset.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] \
    || fail "$preset.png is not a PNG"
  "$mfr" render procedural:bottles --width 256 --height 256 -m "$preset" -M 4MB --quiet \
    -o "$tmp/cli-$preset.png"
  cmp "$tmp/out/$preset.png" "$tmp/cli-$preset.png" || fail "$preset: consumer and CLI differ"
  cmp "$tmp/out-pc/$preset.png" "$tmp/cli-$preset.png" || fail "$preset: pkg-config build differs"
done
notimes='s/"time_ms":\{[^}]*\}//; s/"total_ms":[0-9.e+-]+//'
cmp <(sed -E "$notimes" "$tmp/stats.txt") <(sed -E "$notimes" "$tmp/stats-pc.txt") \
  || fail "the two consumers' statistics differ"

# --- the installed Python module ---------------------------------------------------------------
if [ "$python" != none ]; then
  site=$(find "$prefix" -path '*site-packages/mfr/__init__.py' | head -1)
  [ -n "$site" ] || fail "the Python module is not installed"
  site=$(dirname "$(dirname "$site")")
  (cd "$tmp" && PYTHONPATH="$site" PYTHONDONTWRITEBYTECODE=1 "$python" - "$site" "$tmp" <<'PY'
import os, sys
import numpy as np
import mfr
site, tmp = sys.argv[1], sys.argv[2]
assert mfr.__file__.startswith(site), mfr.__file__
r = mfr.render("procedural:bottles", method="dkb", budget="4MB", width=256, height=256)
assert np.array_equal(r.srgb, mfr.read_png(os.path.join(tmp, "cli-dkb.png")))
print("python: installed module at", os.path.dirname(mfr.__file__), "renders as the CLI")
PY
  ) || fail "the installed Python module"
fi
echo "package: OK ($prefix relocated from staging)"
