#!/usr/bin/env bash
# Set up, build, and run the main job: the default example scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh appell_cli   # the library and the appell command only
mkdir -p out
./build/cli/appell run examples/rolling_disk/rolling_disk.urdf --out out/rolling_disk.csv "$@"
