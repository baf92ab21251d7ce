#!/usr/bin/env bash
# Set up, build, and pass the tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-viewer-deps.sh --browser   # chromium for the viewer's screenshot test
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
