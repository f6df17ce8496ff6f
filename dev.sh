#!/usr/bin/env bash
# Builds ssx from a fresh Debian 12 machine and runs it. Installs what the build needs first.
#
#   ./dev.sh demo   build the ssx command and its plugins, then run the default swarm scenario in
#                   real time (20 s)
#   ./dev.sh test   build, then run every test (ctest)
#   ./dev.sh build  build only
#   ./dev.sh sanitize  the whole suite under ASan+UBSan (clang, build-asan/), each fuzz target for
#                   FUZZ_SECONDS (default 60) in that build, and the parallel and determinism tests
#                   under TSan (build-tsan/)
#
# Environment: BUILD_DIR (default: build), SSX_WARNINGS_AS_ERRORS=ON to fail on warnings (CI),
# JOBS (default: 2), SSX_DEBUG_INFO=lines for line tables only instead of full debug information
# (stack traces and perf keep their lines; a build takes about a quarter less: CI), FUZZ_SECONDS.
set -euo pipefail
cd "$(dirname "$0")"

packages=(build-essential cmake ninja-build pkg-config ccache
          libode-dev libbullet-dev libeigen3-dev libpugixml-dev libcli11-dev catch2 libpng-dev libosmesa6-dev libzstd-dev
          libcivetweb-dev nlohmann-json3-dev libjs-three cyclonedds-dev cyclonedds-tools liburdfdom-dev libassimp-dev libsdformat-dev
          python3-dev python3-numpy pybind11-dev libopenmpi-dev openmpi-bin)
# for `test` also pytest and matplotlib (the Python module's tests and examples), doxygen (the
# API reference and its check), Chromium with selenium and websockets (the viewer's tests), and
# torch (ssx.learn's training example and its test)
python_test_packages=(python3-pytest python3-matplotlib doxygen chromium chromium-driver python3-selenium python3-websockets
                      python3-torch)
# for `test` also ROS 1 (Debian's), so that the ros1 extension is built and tested against a real master
ros_packages=(libroscpp-dev libgeometry-msgs-dev libsensor-msgs-dev libnav-msgs-dev
              python3-rosmaster python3-rospy python3-rostopic python3-geometry-msgs python3-nav-msgs)
# for `sanitize`: clang with its sanitizer and libFuzzer runtimes; Chromium, selenium and websockets,
# so that the viewer's tests run the instrumented ssx
sanitize_packages=(clang libclang-rt-14-dev chromium chromium-driver python3-selenium python3-websockets)
build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-2}
# the flags of the RelWithDebInfo builds: -O2 with full debug information, or line tables only
debug_flags=()
[ "${SSX_DEBUG_INFO:-full}" = lines ] &&
  debug_flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG")

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

# the independent MCAP reader the tests use, from the npm registry, pinned by
# tests/tools/package-lock.json, into DIR/npm (tests only: nothing ssx runs needs Node.js)
install_npm_tools() {
  mkdir -p "$1/npm"
  cp tests/tools/package.json tests/tools/package-lock.json "$1/npm/"
  npm ci --prefix "$1/npm" --no-audit --no-fund >/dev/null
}

# the tests' precompiled header can come from ccache too
export CCACHE_SLOPPINESS=pch_defines,time_macros

# build [TARGET]: configures and builds everything, or only TARGET
build() {
  install_packages
  local launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSSX_WARNINGS_AS_ERRORS="${SSX_WARNINGS_AS_ERRORS:-OFF}" "${launcher[@]}" "${debug_flags[@]}" >/dev/null
  cmake --build "$build_dir" -j "$jobs" ${1:+--target "$1"}
}

case "${1:-}" in
  demo)
    build ssx_runtime  # the command and its plugins: the tests and examples are `test`'s to build
    "$build_dir/bin/ssx" run examples/scenes/formation_sphere.xml --realtime
    ;;
  test)
    packages+=("${ros_packages[@]}" "${python_test_packages[@]}")
    # Node.js for the independent MCAP reader (tests only; a Node.js already there is used as it is)
    command -v node >/dev/null && command -v npm >/dev/null || packages+=(nodejs npm)
    build
    install_npm_tools "$build_dir"
    ctest --test-dir "$build_dir" -j "$jobs" --output-on-failure
    ;;
  build)
    build
    ;;
  sanitize)
    packages+=("${ros_packages[@]}" "${sanitize_packages[@]}")
    command -v node >/dev/null && command -v npm >/dev/null || packages+=(nodejs npm)
    install_packages
    install_npm_tools build-asan
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
    # a finding ends the test that found it, with a stack
    export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
    export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
    export LSAN_OPTIONS=suppressions=$PWD/tests/sanitizers/lsan.supp
    export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/tests/sanitizers/tsan.supp
    CC=clang CXX=clang++ cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSSX_FUZZ=ON \
      -DSSX_WARNINGS_AS_ERRORS="${SSX_WARNINGS_AS_ERRORS:-OFF}" "${launcher[@]}" "${debug_flags[@]}" >/dev/null
    cmake --build build-asan -j "$jobs"
    # install_and_consume builds a plain consumer against the library, which an instrumented
    # libssx cannot link into; the out-of-memory test limits the address space (ulimit -v), in which
    # ASan cannot reserve its shadow memory, and ASan's operator new reports instead of throwing;
    # the Debian package is the plain build's to check (packaging an instrumented build and running
    # it unpacked took 74 s here); the plain build (./dev.sh test) runs all three. The long behavioural scenarios (a thousand e-pucks
    # for a simulated minute, 70 quadrotors forming a sphere: 22 of the 36 minutes of test time the
    # suite takes under ASan) run in the plain build only; the code they run (ground robots,
    # joints, formations, both engines) runs here in the shorter tests. So do the Crazyflie replay
    # sweep and ablation, the replay on Bullet (22 flights) and the fidelity ablation: the same
    # replay and flights as the crazyflie_flight_replay_matches_docs_ode and
    # fidelity_eight_matches_readme_* tests run here. So do the two other passes over the 22 real
    # flights (the mass's two methods, the estimator's table: 98 and 33 s under ASan), whose replays
    # crazyflie_flight_replay_matches_docs_ode runs here too
    ctest --test-dir build-asan -j "$jobs" --output-on-failure \
      -E '^install_and_consume$|^deb_package_runs_unpacked$|memory running out while loading|^ground scenarios: (diffusion|aggregation|foraging):|quadrotors (from random starts )?form the sphere|^crazyflie_flight_replay_(sweep|ablation)_matches_docs$|^crazyflie_flight_replay_matches_docs_bullet$|^fidelity_eight_ablation_lines$|^flight_replay_mass_methods_agree$|^nanobench_estimator_matches_docs$'
    tests/fuzz/run.sh build-asan "${FUZZ_SECONDS:-60}"
    # under TSan: the tests of threads, bitwise results across thread counts, the worker pool and
    # parallel stepping; only the test files that mention them are compiled (a quarter of them)
    tsan_tests='thread|bitwise|worker pool|parallel'
    cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSSX_SANITIZE=thread \
      -DSSX_BUILD_EXAMPLES=OFF -DSSX_WITH_ROS1=OFF -DSSX_WARNINGS_AS_ERRORS="${SSX_WARNINGS_AS_ERRORS:-OFF}" \
      -DSSX_TEST_FILES_MATCHING="$tsan_tests" "${launcher[@]}" "${debug_flags[@]}" >/dev/null
    cmake --build build-tsan -j "$jobs" --target ssx_tests
    ctest --test-dir build-tsan -j "$jobs" --output-on-failure -R "$tsan_tests"
    ;;
  *)
    sed -n '2,15p' "$0"
    exit 2
    ;;
esac
