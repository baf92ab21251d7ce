#!/usr/bin/env bash
# Set up, build, and pass the tests — what CI runs (.ci/run):
#   scripts/test.sh           the whole suite in the Release build (tests, examples,
#                             the Python module, the viewer in headless Chromium),
#                             then a named subset under ASan + UBSan built with
#                             clang and a 30 s fuzz run of the scene loader
#                             (scripts/sanitize.sh). The benchmarks are not built
#                             here: scripts/bench.sh builds and runs them.
#   scripts/test.sh --quick   the fast local loop: the C++ tests only, in their own
#                             build (build-quick: -O1, no Python, viewer or
#                             sanitizers); SANITIZE=0 keeps the Release suite
#                             and skips only the sanitized part.
# Extra arguments go to ctest (e.g. -R Friction). Times on 2 cores: README.md.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--quick" ]; then
  shift
  bash scripts/install-deps.sh
  cmake -S . -B build-quick -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DAPPELL_BUILD_BENCHMARKS=OFF \
    -DAPPELL_BUILD_PYTHON=OFF >/dev/null
  cmake --build build-quick -j"$(nproc)"
  exec ctest --test-dir build-quick --output-on-failure -j"$(nproc)" \
    -E '^(package_consumer|viewer_screenshot)$' "$@"
fi
bash scripts/install-viewer-deps.sh --browser   # chromium for the viewer's screenshot test
APPELL_CMAKE_ARGS="-DAPPELL_BUILD_BENCHMARKS=OFF" bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
if [ "${SANITIZE:-1}" != 0 ]; then
  bash scripts/sanitize.sh
fi
