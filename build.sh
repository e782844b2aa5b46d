#!/usr/bin/env bash
# Sylva on a fresh Debian 12 machine: install what is missing, build, then run the main job or the tests.
#   ./build.sh run    install + build the sylva program only + render the default forest to out/default_forest.png
#   ./build.sh test   install + build + run every test (ctest)
#   ./build.sh build  install + build everything (programs, studio, tests, benchmarks)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
MODE="${1:-run}"
BUILD_DIR="$ROOT/build/release"
JOBS="${SYLVA_JOBS:-$(nproc)}"

PACKAGES=(cmake ninja-build ccache g++ pkg-config
  qt6-base-dev qt6-base-dev-tools libqt6opengl6-dev
  libassimp-dev libopenmesh-dev libopenimageio-dev openimageio-tools libopencv-core-dev
  libglm-dev libtbb-dev libembree-dev
  # OpenVDB grids in and out; xxHash keys of the grid cache
  libopenvdb-dev libboost-iostreams-dev libxxhash-dev
  # sylva-studio's GL tests run under Xvfb with Mesa's software OpenGL
  qt6-qpa-plugins xvfb xauth libgl1-mesa-dri
  # sylva study draws the plots of docs/ACCURACY.md
  gnuplot-nox
  # sylva render --mpi and its tests, see docs/DISTRIBUTED.md
  libopenmpi-dev openmpi-bin
  # OpenColorIO's display transforms (render --view); its tools check them in the tests
  libopencolorio-dev opencolorio-tools
  # the Python module (docs/PYTHON.md) and its test
  pybind11-dev python3-dev python3-numpy)

install_missing() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ((${#missing[@]})); then
    echo "==> installing: ${missing[*]}"
    local sudo=()
    if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
    "${sudo[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${missing[@]}"
  else
    echo "==> all packages present"
  fi
}

# build [TARGET...]: configure, then build the targets (everything when none is named).
build() {
  # nvcc lives outside PATH in a default CUDA install; the build enables CUDA when it finds it.
  if ! command -v nvcc >/dev/null 2>&1 && [[ -x /usr/local/cuda/bin/nvcc ]]; then
    export PATH="/usr/local/cuda/bin:$PATH"
  fi
  echo "==> configuring ($BUILD_DIR)"
  (cd "$ROOT" && cmake --preset release >/dev/null)
  local targets=()
  if (($#)); then targets=(--target "$@"); fi
  echo "==> building ${*:-everything} with $JOBS jobs"
  cmake --build "$BUILD_DIR" -j "$JOBS" "${targets[@]}"
}

run_main_job() {
  local out="$ROOT/out" sylva="$BUILD_DIR/pipeline/sylva"
  mkdir -p "$out"
  echo "==> rendering the default forest (5 grown species, 962 instances, 273 M instanced triangles, 896x448)"
  echo "    the first run grows, voxelizes and lights each species; later runs load the grids from the cache"
  "$sylva" render --stats -o "$out/default_forest.png"
  echo "==> done: $out/default_forest.png"
}

case "$MODE" in
  run) install_missing; build sylva; run_main_job ;;
  test) install_missing; build; cd "$BUILD_DIR" && ctest --output-on-failure -j "$JOBS" ;;
  build) install_missing; build ;;
  *) echo "usage: $0 [run|test|build]" >&2; exit 2 ;;
esac
