#!/usr/bin/env bash
# Builds ssx from a fresh Debian 12 machine and runs it. Installs what the build needs first.
#
#   ./dev.sh demo   build, then run the default swarm scenario in real time
#   ./dev.sh test   build, then run every test (ctest)
#   ./dev.sh build  build only
#
# Environment: BUILD_DIR (default: build), SSX_WARNINGS_AS_ERRORS=ON to fail on warnings (CI),
# JOBS (default: 2).
set -euo pipefail
cd "$(dirname "$0")"

packages=(build-essential cmake ninja-build pkg-config ccache
          libode-dev libeigen3-dev libpugixml-dev libcli11-dev catch2 libpng-dev libosmesa6-dev)
# for `test` also ROS 1 (Debian's), so that the ros1 extension is built and tested against a real master
ros_packages=(libroscpp-dev libgeometry-msgs-dev libsensor-msgs-dev libnav-msgs-dev
              python3-rosmaster python3-rospy python3-rostopic python3-geometry-msgs python3-nav-msgs)
build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-2}

install_packages() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "dev.sh: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
  install_packages
  local launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSSX_WARNINGS_AS_ERRORS="${SSX_WARNINGS_AS_ERRORS:-OFF}" "${launcher[@]}" >/dev/null
  cmake --build "$build_dir" -j "$jobs"
}

case "${1:-}" in
  demo)
    build
    "$build_dir/bin/ssx" run examples/scenes/formation_sphere.xml --realtime
    ;;
  test)
    packages+=("${ros_packages[@]}")
    build
    ctest --test-dir "$build_dir" -j "$jobs" --output-on-failure
    ;;
  build)
    build
    ;;
  *)
    sed -n '2,12p' "$0"
    exit 2
    ;;
esac
