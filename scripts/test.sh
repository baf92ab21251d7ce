#!/usr/bin/env bash
# Set up, build, and pass the tests — what CI runs (.ci/run):
#   scripts/test.sh           the whole suite in the Release build (./build:
#                             tests, examples, the Python module, the viewer in
#                             headless Chromium), then a
#                             named subset under ASan + UBSan and a 30 s fuzz run
#                             of the scene and mesh loaders (scripts/sanitize.sh,
#                             ./build-asan). The sanitized build compiles beside
#                             the Release one, at lower priority, so the two
#                             cores never wait on a serial step (a configure, a
#                             link, the last tests). The benchmarks are not built
#                             here: scripts/bench.sh builds and runs them.
#   scripts/test.sh --quick   the fast local loop: the C++ tests only, in their own
#                             build (build-quick: -O1, no Python, viewer
#                             or sanitizers); SANITIZE=0 keeps the Release suite
#                             and skips only the sanitized part.
# Extra arguments go to ctest (e.g. -R Friction). Times on 2 cores, and why
# the Release build is not compiled with clang (yet): README.md, "Building".
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
if [ "${1:-}" = "--quick" ]; then
  shift
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
  # Its own session, so that leaving early (a failed build or test) stops it.
  setsid nice -n 10 bash scripts/sanitize.sh --build > build-asan/build.log 2>&1 &
  asan=$!
  trap 'kill -- -"$asan" 2>/dev/null || true' EXIT
fi
APPELL_CMAKE_ARGS="-DAPPELL_BUILD_BENCHMARKS=OFF" bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
if [ -n "$asan" ]; then
  if ! wait "$asan"; then
    trap - EXIT
    echo "test.sh: the sanitized build failed; build-asan/build.log:" >&2
    tail -n 60 build-asan/build.log >&2
    exit 1
  fi
  trap - EXIT
  bash scripts/sanitize.sh
fi
