#!/usr/bin/env bash
# Set up, build, and pass the tests: the whole suite in the Release build,
# then a named subset under ASan + UBSan built with clang and a 30 s fuzz
# run of the scene loader (scripts/sanitize.sh; SANITIZE=0 skips that part
# for a quick local run — CI runs all of it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-viewer-deps.sh --browser   # chromium for the viewer's screenshot test
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
if [ "${SANITIZE:-1}" != 0 ]; then
  bash scripts/sanitize.sh
fi
