#!/usr/bin/env bash
# The two set-up commands of the README:
#   bash tools/run.sh demo   installs what is missing, builds, runs the main job
#   bash tools/run.sh test   installs what is missing, builds, runs every test (CTest)
# Both are idempotent and quick when nothing changed. Run as root on Debian 12 (or with sudo).
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config
  cyclonedds-dev cyclonedds-tools
  libeigen3-dev libyaml-cpp-dev libcli11-dev libnanoflann-dev
  libopencv-dev libpcl-dev libmodbus-dev
  libzstd-dev liblz4-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  zlib1g-dev libpng-dev
  gnuplot-nox
  clang libclang-rt-14-dev nodejs
)
BUILD_DIR=${AVS_BUILD_DIR:-build}
JOBS=${AVS_JOBS:-$(nproc)}

install_missing() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing: ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -q
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
  fi
}

build() {
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release ${AVS_CMAKE_ARGS:-}
  fi
  cmake --build "$BUILD_DIR" -j "$JOBS"
}

case "${1:-}" in
  demo)
    install_missing
    build
    shift
    exec "$BUILD_DIR/tools/avs" demo "$@"
    ;;
  test)
    install_missing
    build
    cd "$BUILD_DIR"
    exec ctest --output-on-failure -j "$JOBS" --timeout 600
    ;;
  *)
    echo "usage: bash tools/run.sh demo|test" >&2
    exit 2
    ;;
esac
