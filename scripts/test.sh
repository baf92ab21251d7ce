#!/usr/bin/env bash
# Set up, build, and pass the tests — what CI runs (.ci/run):
#   scripts/test.sh           the whole suite in the Release build (./build:
#                             tests, examples, the Python module, the viewer in
#                             headless Chromium), a named subset under ASan +
#                             UBSan, then a 30 s fuzz run of the scene and mesh
#                             loaders (scripts/sanitize.sh, ./build-asan). The
#                             sanitized build and its tests run beside the
#                             Release build, at lower priority, so the two
#                             cores never wait on a serial step (a configure, a
#                             link, the last tests). The benchmarks are not built
#                             here: scripts/bench.sh builds and runs them.
#   scripts/test.sh --quick   the fast local loop: the C++ tests only, in their own
#                             build (build-quick: clang, -O1, no Python, browser
#                             or sanitizers; three.js for `appell view` is
#                             installed, its tests need it); SANITIZE=0 keeps the
#                             Release suite and skips only the sanitized part.
# Extra arguments go to ctest (e.g. -R Friction). Times on 2 cores, and why
# the builds are compiled with clang: README.md, "Building".
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# A new build tree is compiled by clang when no compiler is asked for (CXX):
# the same sources in ~35 % less CPU than g++, the same trajectories bit for
# bit (README, "Building"). An existing tree keeps the compiler it has.
prefer_clang() {
  if [ ! -f "$1/CMakeCache.txt" ] && [ -z "${CXX:-}" ] && command -v clang++ >/dev/null; then
    export CC=clang CXX=clang++
  fi
}
if [ "${1:-}" = "--quick" ]; then
  shift
  # three.js, which `appell view` embeds and its C++ tests (CliPlot.View*)
  # open; not the browser (the screenshot test is not in this loop).
  bash scripts/install-viewer-deps.sh
  prefer_clang build-quick
  cmake -S . -B build-quick -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DAPPELL_BUILD_BENCHMARKS=OFF \
    -DAPPELL_BUILD_PYTHON=OFF >/dev/null
  cmake --build build-quick -j"$(nproc)"
  exec ctest --test-dir build-quick --output-on-failure -j"$(nproc)" \
    -E '^(package_consumer|viewer_screenshot)$' "$@"
fi
# three.js for `appell view` and chromium for the viewer's screenshot test;
# before the sanitized build starts, so that no two apt-get runs overlap.
bash scripts/install-viewer-deps.sh --browser
asan=""
if [ "${SANITIZE:-1}" != 0 ]; then
  mkdir -p build-asan
  # The sanitized build and its tests, in their own session (leaving early, on
  # a failed build or test, stops them) and at lower priority: they take what
  # the Release build leaves idle, and their tests run while it still compiles.
  setsid nice -n 10 bash scripts/sanitize.sh --test > build-asan/test.log 2>&1 &
  asan=$!
  trap 'kill -- -"$asan" 2>/dev/null || true' EXIT
fi
prefer_clang build
APPELL_CMAKE_ARGS="-DAPPELL_BUILD_BENCHMARKS=OFF" bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
if [ -n "$asan" ]; then
  status=0
  wait "$asan" || status=$?
  trap - EXIT
  if [ "$status" != 0 ]; then
    echo "test.sh: the sanitized build or its tests failed; build-asan/test.log:" >&2
    tail -n 80 build-asan/test.log >&2
    exit 1
  fi
  echo "== the sanitized subset (build-asan/test.log)"
  sed -n '/^Test project/,$p' build-asan/test.log
  bash scripts/sanitize.sh --fuzz
fi
