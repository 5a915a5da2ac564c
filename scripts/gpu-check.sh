#!/usr/bin/env bash
# The prepared real-GPU check: every preset on the GL engine's native raster against the CPU engine
# at 1024x1024 on layers, bottles, the Dish and hairball, one CSV (bench/gpu_check.cpp; its columns:
# docs/GL_ENGINE.md, "Running on a real GPU"). Prints the GL renderer, version, vendor and the
# extensions that decide the capture (fragment shader interlock, 64-bit atomics) first.
#
#   scripts/gpu-check.sh [--build-dir DIR] [--no-build] [--libs BUNDLE] [--out DIR] [--quick]
#                        [GPU_CHECK_OPTIONS...]
#   scripts/gpu-check.sh --prepare BUNDLE [--build-dir DIR]
#
# Building: with a build folder configured from this checkout and a compiler, gpu_check is
# (re)built there as needed (cmake --build DIR --target gpu_check); else an existing DIR/gpu_check
# is used as it is (a build made elsewhere); with neither, a build folder is configured and built.
# --no-build never builds. DIR defaults to build, or BUNDLE/bin with --libs.
#
# A machine with a GPU and no network (no compiler, no mfr runtime libraries):
#   1. where there is network, on x86-64 Debian/Ubuntu:  scripts/gpu-check.sh --prepare BUNDLE
#      builds gpu_check if needed and fills BUNDLE with bin/gpu_check, debs/ (the Debian packages
#      of the libraries `ldd` shows it needs: libepoxy0, libtbb12, libassimp5 and theirs, not libc6,
#      libgcc-s1 or libstdc++6), gl/ (the GL loaders libegl1 libglvnd0 libopengl0 libgl1 libglx0
#      libgles2) and scenes/ (the Dish, where ../shared/scenes has it), by `apt-get download`.
#   2. carry BUNDLE there (e.g. inside the checkout, ignored by git) and run
#      scripts/gpu-check.sh --libs BUNDLE [--out DIR]
#      which unpacks debs/ with `dpkg -x` into the private prefix BUNDLE/prefix (never into /) and
#      puts on LD_LIBRARY_PATH only the libraries the system lacks (BUNDLE/lib: links into the
#      prefix), and, where the system has no libEGL.so.1, unpacks gl/ into / and runs ldconfig, as
#      the device tool's README does for the GL loaders (root only; else they go to the prefix).
# On any machine: where no EGL vendor file is installed but the NVIDIA driver's is
# (/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json), __EGL_VENDOR_LIBRARY_FILENAMES names
# it, and /usr/local/nvidia/lib64 is searched when ldconfig does not know libEGL_nvidia.so.0.
#
# Every other option goes to gpu_check: --size N (default 1024), --reps N (timed GL renders per
# preset, default 3), --threads N, --scenes LIST, --presets LIST, --dish PATH, --budget M,
# --time-limit S (default 450: the whole run stays under about 8 minutes), --quick (scenes layers
# and bottles at 256x256, one timed render; a smoke test, e.g. on llvmpipe). Output: DIR (default
# gpu-check-results)/gpu-check.csv. Exit status: gpu_check's (0 every row agrees, 1 a row differs
# or failed, 2 a bad command line, 3 no GL 4.5 context), or 4 when this script cannot run it.
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="" prepare="" libs="" no_build=0
pass=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --build-dir | --prepare | --libs)
      if [[ $# -lt 2 ]]; then
        echo "gpu-check.sh: $1 needs a folder" >&2
        exit 2
      fi
      case $1 in
        --build-dir) build=$2 ;;
        --prepare) prepare=$2 ;;
        --libs) libs=$2 ;;
      esac
      shift 2
      ;;
    --no-build)
      no_build=1
      shift
      ;;
    -h | --help)
      sed -n '2,/^set -uo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'
      exit 0
      ;;
    *)
      pass+=("$1")
      shift
      ;;
  esac
done

die() {
  echo "gpu-check.sh: $*" >&2
  exit 4
}

if [[ -z $build ]]; then
  build=build
  [[ -n $libs && -x $libs/bin/gpu_check ]] && build=$libs/bin
fi
exe=$build/gpu_check

have_compiler() {
  command -v cmake >/dev/null 2>&1 && { command -v c++ || command -v g++; } >/dev/null 2>&1
}

# a build folder configured from this checkout, whose compiler is here
configured_here() {
  local cache=$build/CMakeCache.txt compiler
  [[ -f $cache ]] && command -v cmake >/dev/null 2>&1 || return 1
  grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$root" "$cache" || return 1
  compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$cache")
  [[ -n $compiler && -x $compiler ]]
}

ensure_binary() {
  if ((no_build)); then
    [[ -x $exe ]] || die "$exe not found (--no-build)"
  elif configured_here; then
    echo "gpu-check.sh: building gpu_check in $build where out of date"
    cmake --build "$build" --target gpu_check -j "$(nproc)" >"$build/gpu-check-build.log" 2>&1 ||
      die "the build failed: $build/gpu-check-build.log"
  elif [[ -x $exe ]]; then
    echo "gpu-check.sh: using $exe as it is (a build made elsewhere)"
  elif have_compiler; then
    echo "gpu-check.sh: configuring and building gpu_check in $build"
    { cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release &&
      cmake --build "$build" --target gpu_check -j "$(nproc)"; } >"$build.gpu-check-build.log" 2>&1 ||
      die "the build failed: $build.gpu-check-build.log"
  else
    die "$exe not found and no compiler here: build it elsewhere (scripts/gpu-check.sh --prepare BUNDLE), then --libs BUNDLE or --build-dir DIR"
  fi
}

# The Debian package that holds a library path (merged /usr or not), without the architecture.
package_of() {
  local path=$1 real p
  real=$(readlink -f "$path")
  for p in "$path" "$real" "/usr$path" "${path#/usr}" "/usr$real" "${real#/usr}"; do
    dpkg -S "$p" 2>/dev/null | sed -n '1s/:.*//p' | grep . && return 0
  done
  return 1
}

do_prepare() {
  local bundle=$1 lib pkg dish
  [[ $(dpkg --print-architecture 2>/dev/null) == amd64 ]] ||
    die "--prepare runs on x86-64 Debian/Ubuntu (the GPU machine's processor); dpkg says '$(dpkg --print-architecture 2>/dev/null)'"
  ensure_binary
  mkdir -p "$bundle/bin" "$bundle/debs" "$bundle/gl" || die "cannot write $bundle"
  cp "$exe" "$bundle/bin/gpu_check" || die "cannot copy $exe"
  local gl_pkgs=(libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
  local pkgs=(libepoxy0 libtbb12 libassimp5)
  while read -r lib; do
    pkg=$(package_of "$lib") || {
      echo "gpu-check.sh: no Debian package holds $lib: not in the bundle" >&2
      continue
    }
    case " libc6 libgcc-s1 libstdc++6 ${gl_pkgs[*]} " in
      *" $pkg "*) ;;
      *) pkgs+=("$pkg") ;;
    esac
  done < <(ldd "$exe" | awk '$2 == "=>" && $3 ~ /^\// {print $3}')
  mapfile -t pkgs < <(printf '%s\n' "${pkgs[@]}" | sort -u)
  echo "gpu-check.sh: downloading ${pkgs[*]} into $bundle/debs"
  (cd "$bundle/debs" && apt-get download "${pkgs[@]}") || die "apt-get download failed"
  echo "gpu-check.sh: downloading the GL loaders ${gl_pkgs[*]} into $bundle/gl"
  (cd "$bundle/gl" && apt-get download "${gl_pkgs[@]}") || die "apt-get download failed"
  dish=$root/../shared/scenes/khronos/IridescentDishWithOlives/glTF
  if [[ -d $dish ]]; then
    mkdir -p "$bundle/scenes/IridescentDishWithOlives"
    cp -r "$dish" "$bundle/scenes/IridescentDishWithOlives/" || die "cannot copy $dish"
  else
    echo "gpu-check.sh: $dish not found: the bundle has no Dish (gpu_check skips it)"
  fi
  echo "gpu-check.sh: $bundle ready ($(du -sh "$bundle" | cut -f1)); on the GPU machine:"
  echo "  scripts/gpu-check.sh --libs $bundle [--out DIR]"
}

# sonames that the binary's dynamic linker does not find
missing_libs() {
  ldd "$exe" 2>/dev/null | awk '$2 == "=>" && $3 == "not" {print $1}'
}

use_libs() {
  local bundle=$1 f soname found _ prefix=$1/prefix
  command -v dpkg >/dev/null 2>&1 || die "--libs needs dpkg (dpkg -x)"
  mkdir -p "$prefix" "$bundle/lib" || die "cannot write $bundle"
  if ! ldconfig -p 2>/dev/null | grep -q 'libEGL\.so\.1 '; then
    if [[ $(id -u) == 0 ]] && compgen -G "$bundle/gl/*.deb" >/dev/null; then
      echo "gpu-check.sh: no libEGL.so.1: unpacking the GL loaders of $bundle/gl into / (ldconfig)"
      for f in "$bundle"/gl/*.deb; do dpkg -x "$f" / || die "dpkg -x $f / failed"; done
      ldconfig
    else
      echo "gpu-check.sh: no libEGL.so.1 and not root: the GL loaders go to the private prefix"
      for f in "$bundle"/gl/*.deb; do [[ -f $f ]] && dpkg -x "$f" "$prefix"; done
    fi
  fi
  for f in "$bundle"/debs/*.deb; do
    [[ -f $f ]] && { dpkg -x "$f" "$prefix" || die "dpkg -x $f failed"; }
  done
  export LD_LIBRARY_PATH="$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  # link what is missing, then what the linked libraries miss in turn
  for _ in 1 2 3 4 5 6 7 8; do
    found=0
    while read -r soname; do
      f=$(find "$prefix" -name "$soname" \( -type f -o -type l \) -print -quit)
      if [[ -n $f ]]; then
        ln -sf "$(readlink -f "$f")" "$bundle/lib/$soname"
        found=1
      fi
    done < <(missing_libs)
    ((found)) || break
  done
  if [[ -n $(missing_libs) ]]; then
    echo "gpu-check.sh: still missing after --libs $bundle: $(missing_libs | tr '\n' ' ')" >&2
  fi
  echo "gpu-check.sh: libraries from $bundle: $(find "$bundle/lib" -mindepth 1 -printf '%f ')"
}

nvidia_egl() {
  local json=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json d
  if [[ -z ${__EGL_VENDOR_LIBRARY_FILENAMES:-} && -f $json ]] &&
    ! compgen -G "/usr/share/glvnd/egl_vendor.d/*.json" >/dev/null &&
    ! compgen -G "/etc/glvnd/egl_vendor.d/*.json" >/dev/null; then
    export __EGL_VENDOR_LIBRARY_FILENAMES=$json
    echo "gpu-check.sh: no EGL vendor installed: __EGL_VENDOR_LIBRARY_FILENAMES=$json"
  fi
  if ! ldconfig -p 2>/dev/null | grep -q 'libEGL_nvidia\.so\.0 '; then
    for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do
      [[ -e $d/libEGL_nvidia.so.0 ]] && export LD_LIBRARY_PATH="${LD_LIBRARY_PATH:+$LD_LIBRARY_PATH:}$d"
    done
  fi
}

if [[ -n $prepare ]]; then
  do_prepare "$prepare"
  exit 0
fi

ensure_binary
[[ -n $libs ]] && use_libs "$libs"
nvidia_egl
[[ -n $(missing_libs) ]] &&
  die "$exe cannot start, missing $(missing_libs | tr '\n' ' ')(see --prepare and --libs)"

args=("${pass[@]}")
if [[ -n $libs && -f $libs/scenes/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf ]] &&
  [[ " ${pass[*]} " != *" --dish "* ]]; then
  args+=(--dish "$libs/scenes/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf")
fi
[[ " ${pass[*]} " == *" --out "* ]] || args+=(--out gpu-check-results)

echo "gpu-check.sh: $exe ${args[*]}"
start=$SECONDS
log=$(mktemp) || die "mktemp failed"
"$exe" "${args[@]}" 2>&1 | tee "$log"
status=${PIPESTATUS[0]}
if grep -q '^  renderer .*llvmpipe' "$log" &&
  { command -v nvidia-smi >/dev/null 2>&1 || [[ -d /usr/local/nvidia ]]; }; then
  echo "gpu-check.sh: warning: the GL context is Mesa's llvmpipe on a machine with an NVIDIA driver (EGL vendor files: /usr/share/glvnd/egl_vendor.d)" >&2
fi
rm -f "$log"
echo "gpu-check.sh: exit $status after $((SECONDS - start)) s"
exit "$status"
