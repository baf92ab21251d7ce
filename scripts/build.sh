#!/usr/bin/env bash
# Configures and builds appell (Release) into ./build. Used by run.sh, test.sh
# and bench.sh.
#   scripts/build.sh            everything configured (library, CLI, tests, examples,
#                               the Python module; benchmarks when configured on)
#   scripts/build.sh TARGET…    only those targets and what they need (run.sh: appell_cli)
# APPELL_CMAKE_ARGS adds configure options: test.sh turns the benchmarks off,
# bench.sh on (the cache keeps the last choice for a plain build).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/install-viewer-deps.sh   # three.js for `appell view` (npm ci, seconds)
# shellcheck disable=SC2086  # word splitting of the options is intended
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release ${APPELL_CMAKE_ARGS:-} >/dev/null
if [ $# -gt 0 ]; then
  cmake --build build -j"$(nproc)" --target "$@"
else
  cmake --build build -j"$(nproc)"
fi
