#!/usr/bin/env bash
# Configures and builds appell (Release) into ./build. Used by run.sh and test.sh.
#   scripts/build.sh            everything (library, CLI, tests, benchmarks, examples)
#   scripts/build.sh TARGET…    only those targets and what they need (run.sh: appell_cli)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/install-viewer-deps.sh   # three.js for `appell view` (npm ci, seconds)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ $# -gt 0 ]; then
  cmake --build build -j"$(nproc)" --target "$@"
else
  cmake --build build -j"$(nproc)"
fi
