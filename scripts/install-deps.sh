#!/usr/bin/env bash
# Installs every Debian package mfr needs to build, test and benchmark. Idempotent: packages already
# present are not touched, and `apt-get update` runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libtbb-dev            # tiled parallel rasterizer (oneTBB)
  libcli11-dev          # command line
  nlohmann-json3-dev    # JSON scenes, --json, stats
  libglm-dev            # vector maths
  libeigen3-dev         # the deep k-buffer's network (training and inference)
  libstb-dev            # PNG/JPEG read (textures), PNG write
  libtinygltf-dev       # glTF 2.0 loader
  libtinyobjloader-dev  # Wavefront OBJ + MTL loader
  libassimp-dev         # PLY loader
  libgtest-dev libgmock-dev
  libbenchmark-dev
  gnuplot-nox           # benchmark plots (scripts/bench.sh)
  python3               # evaluation tables (scripts/eval_tables.py)
  pybind11-dev python3-pybind11 python3-dev python3-numpy  # the Python module mfr (python/)
  python3-pytest        # its tests (python/tests, run by ctest)
  libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri  # the OpenGL 4.5 engine (headless EGL)
  glslang-tools         # every GL shader variant validated in the tests (glslangValidator)
  libglfw3-dev libimgui-dev  # mfr view: window and panel (ImGui backends from its examples)
  xvfb xauth xdotool    # mfr view tests under a virtual X server (xvfb-run), real input events
  chromium              # the mfr compare report in headless Chromium (tests/report_chromium_test.sh)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
